//! Issue 26 item 7: PBTF's loops inside each octant nested k, j, i (`order::pbtf`) against
//! Westover's per-view choice (`order::wbtf_axes`), both visibility orders (the seed's "or
//! duals"), scored by the image-space validator on the README's views and the rmnp fly-over, 256².
use voxsplat::order::{count_pixel_inversions, pbtf_nested, pbtf_split, wbtf_axes};
use voxsplat::{camera::Projection, order::Direction, Camera};

/// A nesting per octant.
type Nesting<'a> = &'a dyn Fn(u32) -> [usize; 3];

fn main() -> voxsplat::Result<()> {
    let cube = voxsplat::scene::build("cube60")?;
    let rmnp = voxsplat::scene::build("rmnp")?;
    let at = |set: &voxsplat::SplatSet, eye: [f32; 3], target: [f32; 3]| Camera {
        eye: eye.into(),
        target: target.into(),
        projection: Projection::Perspective { fov_y_deg: 75.0 },
        near: 0.5,
        far: 500.0,
        ..Camera::framing(set.grid(), 256, 256)
    };
    let views = [
        ("cube60 view A", &cube, at(&cube, [70.0, 20.0, 12.0], [0.0; 3])),
        ("cube60 view B", &cube, at(&cube, [20.0, 40.0, 50.0], [-40.0, -10.0, -10.0])),
        ("rmnp fly-over", &rmnp, Camera::flyover(rmnp.grid(), 256, 256)),
    ];
    println!("| view | nesting | pixel inversions | in pixels | apart |\n|---|---|---:|---:|---:|");
    for (name, set, cam) in views {
        let split = pbtf_split(set, &cam);
        let octants = voxsplat::order::octant_axes(set, &cam, split);
        let per_octant = |o: u32| octants[o as usize];
        let view_axes = wbtf_axes(&cam);
        let choices: [(&str, Nesting); 3] = [
            ("k, j, i", &|_| [2, 1, 0]),
            ("Westover's, per view", &|_| view_axes),
            ("Westover's, per octant", &per_octant),
        ];
        for (label, axes) in choices {
            let mut seq = pbtf_nested(set, split, axes);
            seq.reverse();
            let p = count_pixel_inversions(set, &cam, &seq, Direction::BackToFront, 2.0)?;
            println!("| {name} | {label} | {} | {} | {} |", p.inversions, p.pixels, p.separated);
        }
    }
    Ok(())
}
