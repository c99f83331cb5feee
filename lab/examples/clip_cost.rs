//! What clipping saves on a bricked volume (issue 27 item 2): the bonsai at 512² (the framing
//! view, tile compositor, front to back), uncropped, cropped to one octant of its box, and cut by
//! a plane through its middle; median frame times of five rounds with the variants alternating in
//! one process, and the covered pixels of each.
//!
//! `cargo run --release -p voxsplat-lab --example clip_cost [-- FILE [TF]]`
use glam::Vec4;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::{options::Clip, options::Raster, order::Direction, Camera, RenderOptions, Renderer, RendererOptions};

fn main() -> voxsplat::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map_or("../shared/data/bonsai/bonsai.nii.gz", |s| s.as_str());
    let tf = args.get(1).map_or("bonsai", |s| s.as_str());
    let store = BrickStore::load(path.as_ref(), &Default::default())?;
    let grid = store.grid()?;
    let cam = Camera::framing(&grid, 512, 512);
    let mut r = Renderer::new(&RendererOptions::default())?;
    r.set_bricks(BrickScene::new(store, TransferFunction::preset(tf)?, None)?)?;
    let (lo, hi) = (grid.position([0, 0, 0]), grid.position(grid.dims.map(|d| d - 1)));
    let variants = [
        ("whole", Clip::default()),
        ("one octant (crop)", Clip::new(&[], Some([lo, lo.lerp(hi, 0.5)]))?),
        ("half (plane x < centre)", Clip::new(&[Vec4::new(-1.0, 0.0, 0.0, grid.center().x)], None)?),
    ];
    let options = |clip: Clip| {
        let mut o = RenderOptions::default();
        (o.raster, o.direction, o.clip) = (Raster::Compute, Some(Direction::FrontToBack), clip);
        o
    };
    let times = voxsplat_lab::bench::alternating_medians(variants.len(), 1, 5, |v| {
        voxsplat_lab::bricked::frame_ms(&mut r, &cam, &options(variants[v].1))
    })?;
    println!("| clip | covered px | median ms | vs whole |\n|---|---:|---:|---:|");
    for ((name, clip), ms) in variants.iter().zip(&times) {
        let img = r.render(&cam, &options(*clip))?.image;
        let covered = img.pixels.iter().filter(|p| p[3] > 0.0).count();
        println!("| {name} | {covered} | {ms:.1} | {:.2}× |", ms / times[0]);
    }
    Ok(())
}
