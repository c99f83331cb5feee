//! Built-in scenes reproducing the dissertation's test objects, listed by name.
//!
//! ```
//! use voxsplat::scene;
//! // The built-in scenes (`voxsplat render --list`): here the hollow 40^3 cube, one voxel thick.
//! let set = scene::build("cube40")?;
//! assert_eq!(set.len(), 40 * 40 * 40 - 38 * 38 * 38);
//! assert!(scene::build("no-such-scene").is_err());
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::{Camera, Projection};
use crate::error::{Error, Result};
use crate::kernel::Kernel;
use crate::volume::{Grid, SplatSet};
use glam::Vec3;

pub mod peer;

/// Opacity of one voxel-length of the built-in materials.
pub const SCENE_OPACITY: f32 = 0.95;
const RED: [f32; 3] = [0.85, 0.1, 0.1];
/// The checkerboard's white.
pub const WHITE: [f32; 3] = [0.95, 0.95, 0.95];
/// The checkerboard's black.
pub const BLACK: [f32; 3] = [0.08, 0.08, 0.08];

/// (name, description) of every built-in scene.
pub const SCENES: &[(&str, &str)] = &[
    ("cube40", "hollow 40^3 cube, one voxel thick, alternating 10^3 red/white sub-cubes (Figs 1.13-1.15, 1.17)"),
    ("cube60", "hollow 60^3 cube, one voxel thick, alternating 10^3 red/white sub-cubes (Figs 1.16, 2.25-2.27)"),
    ("cube40-attenuated", "cube40 with opacity 0.3: semi-transparent splats (Fig. 1.14)"),
    ("solid40", "filled 40^3 cube, opacity 0.95, the sub-cube texture: opaque data for early termination"),
    ("plane", "single-sheet 498x398x1 checkerboard of 10x10 black/white squares (Fig. 3.6)"),
    ("stripes128", "dense 128^3 ball with 3-voxel colour stripes, semi-transparent: finer than the pixels in small views (Fig. 3.8)"),
    ("empty", "an 8^3 grid with no non-empty voxel"),
    ("peer128", "the peers' synthetic 128^3 volume and transfer function (../shared/peers: VTK and taichi render the same scene)"),
    ("peer256", "the same at 256^3"),
    ("bonsai", "data: CT of a bonsai, 256^3 NIfTI (shared/data/bonsai), 'bonsai' transfer function"),
    ("stent", "data: CT of a stented aorta, 128x128x256 NRRD (shared/data/stent), 'ct' transfer function"),
    ("rmnp", "data: Rocky Mountain NP elevation, 152x187 GeoTIFF with Landsat colour (shared/data/rmnp), x3 relief"),
];

fn hollow_cube(n: u32, opacity: f32) -> Result<SplatSet> {
    textured_cube(n, opacity, false)
}

fn textured_cube(n: u32, opacity: f32, solid: bool) -> Result<SplatSet> {
    let grid = Grid::centered([n, n, n], [1.0; 3])?;
    SplatSet::from_fn(grid, |i, j, k| {
        let shell = solid || [i, j, k].iter().any(|&c| c == 0 || c == n - 1);
        shell.then(|| {
            let c = if (i / 10 + j / 10 + k / 10) % 2 == 0 { RED } else { WHITE };
            [c[0], c[1], c[2], opacity]
        })
    })
}

/// Build a scene by name.
pub fn build(name: &str) -> Result<SplatSet> {
    match name {
        "cube40" => hollow_cube(40, SCENE_OPACITY),
        "cube60" => hollow_cube(60, SCENE_OPACITY),
        "cube40-attenuated" => hollow_cube(40, 0.3),
        "solid40" => textured_cube(40, SCENE_OPACITY, true),
        "plane" => {
            let grid = Grid::centered([498, 398, 1], [1.0; 3])?;
            SplatSet::from_fn(grid, |i, j, _| {
                let c = if (i / 10 + j / 10) % 2 == 0 { BLACK } else { WHITE };
                Some([c[0], c[1], c[2], SCENE_OPACITY])
            })
        }
        "stripes128" => {
            let grid = Grid::centered([128, 128, 128], [1.0; 3])?;
            SplatSet::from_fn(grid, |i, j, k| {
                let d = [i, j, k].map(|c| c as f32 - 63.5);
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                (r2 < 60.0 * 60.0).then(|| {
                    let c = if (i / 3 + j / 3) % 2 == 0 { RED } else { WHITE };
                    [c[0], c[1], c[2], 0.04]
                })
            })
        }
        "empty" => SplatSet::from_fn(Grid::centered([8, 8, 8], [1.0; 3])?, |_, _, _| None),
        "peer128" | "peer256" => {
            let n = peer::side_of(name).expect("matched above");
            crate::classify::classify(&peer::volume(n)?, &peer::transfer_function(), None)
        }
        #[cfg(feature = "io")]
        "bonsai" | "stent" => {
            let dir = crate::loaders::data_dir();
            let (file, tf) =
                if name == "bonsai" { ("bonsai/bonsai.nii.gz", "bonsai") } else { ("stent/stent.nrrd", "ct") };
            let vol = crate::loaders::load_volume(&dir.join(file), &Default::default())?;
            crate::classify::classify(&vol, &crate::classify::TransferFunction::preset(tf)?, None)
        }
        #[cfg(feature = "io")]
        "rmnp" => {
            let dir = crate::loaders::data_dir().join("rmnp");
            let heights = crate::loaders::load_heights(&dir.join("rmnp-dem.tif"))?;
            let color = image::open(dir.join("rmnp-rgb.png"))
                .map_err(|e| Error::InvalidArgument(format!("rmnp-rgb.png: {e}")))?
                .to_rgba8();
            let opts =
                crate::terrain::TerrainOptions { cell: 233.0, vscale: 3.0, color: Some(color), ..Default::default() };
            crate::terrain::terrain_splats(&heights, &opts)
        }
        #[cfg(not(feature = "io"))]
        "bonsai" | "stent" | "rmnp" => {
            Err(Error::Unsupported(format!("scene '{name}' reads ../shared/data: build voxsplat with the io feature")))
        }
        other => Err(Error::InvalidArgument(format!(
            "unknown scene '{other}'; built-in scenes: {}",
            SCENES.iter().map(|s| s.0).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// The close, off-axis perspective view of the 60³ cube of Figs 2.25–2.27 (the eye projects inside
/// the grid on two axes).
pub fn close_view(grid: &Grid, size: u32) -> Camera {
    let c = grid.center();
    Camera {
        eye: c + Vec3::new(12.0, 20.0, 75.0),
        target: c,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 60.0 },
        near: 0.5,
        far: 300.0,
        width: size,
        height: size,
        window: None,
    }
}

/// The sweep's sheet of `n` x `n` voxels.
pub fn rate_scene(n: u32) -> Result<SplatSet> {
    let grid = Grid::centered([n, n, 1], [1.0; 3])?;
    SplatSet::from_fn(grid, |i, j, _| {
        let c = if (i / 4 + j / 4) % 2 == 0 { [0.9, 0.3, 0.1] } else { [0.2, 0.5, 0.9] };
        Some([c[0], c[1], c[2], 0.3])
    })
}

/// Head-on orthographic view of `grid` (a sheet) with footprints `size_px` wide.
pub fn rate_camera(grid: &Grid, size_px: f32) -> Result<Camera> {
    if !(size_px.is_finite() && size_px >= 1.0) {
        return Err(Error::InvalidArgument(format!("footprint size {size_px} px must be at least 1")));
    }
    let ppv = size_px / (2.0 * Kernel::Gaussian.radius());
    let extent = grid.dims[0].max(grid.dims[1]) as f32 + 2.0 * Kernel::Gaussian.radius();
    let side = (extent * ppv).ceil() as u32;
    let c = grid.center();
    Ok(Camera {
        eye: c + Vec3::new(0.0, 0.0, 50.0),
        target: c,
        up: Vec3::Y,
        projection: Projection::Orthographic { height: side as f32 / ppv },
        near: 1.0,
        far: 100.0,
        width: side,
        height: side,
        window: None,
    })
}
