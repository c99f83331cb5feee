//! Loaders, classification and terrain (chapter 5): round trips, malformed input in seeded loops,
//! hole filling, fly-over visibility, and the real-data presets on GPU and CPU.
use super::common;
use crate::loaders::{nifti_from_bytes, npy_from_bytes, nrrd_from_bytes, raw_from_bytes, tiff_heights, DType};
use crate::order::{count_violations, visibility_order};
use crate::terrain::{terrain_splats, TerrainOptions};
use crate::RaycastOptions;
use crate::{Camera, Direction, OrderKind};
use common::Rng;
use std::io::Write;

const DIMS: [u32; 3] = [7, 5, 4];

fn values() -> Vec<f32> {
    (0..140).map(|i| ((i * 37) % 251) as f32).collect()
}

fn u16_bytes(v: &[f32], big: bool) -> Vec<u8> {
    v.iter().flat_map(|&x| if big { (x as u16).to_be_bytes() } else { (x as u16).to_le_bytes() }).collect()
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn nrrd(encoding: &str, payload: &[u8]) -> Vec<u8> {
    let mut b = format!(
        "NRRD0004\n# test\ntype: unsigned short\ndimension: 3\nsizes: 7 5 4\nspacings: 1 2 0.5\nendian: little\nencoding: {encoding}\n\n"
    )
    .into_bytes();
    b.extend_from_slice(payload);
    b
}

fn nifti(v: &[f32]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dim: [i16; 8] = [3, 7, 5, 4, 1, 1, 1, 1];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&512i16.to_le_bytes()); // uint16
    h[72..74].copy_from_slice(&16i16.to_le_bytes());
    let pix: [f32; 8] = [1.0, 1.0, 2.0, 0.5, 1.0, 1.0, 1.0, 1.0];
    for (i, p) in pix.iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&1f32.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h.extend_from_slice(&u16_bytes(v, false));
    h
}

fn tiff_u16(w: u32, h: u32, v: &[u16]) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let mut enc = tiff::encoder::TiffEncoder::new(&mut out).unwrap();
    enc.write_image::<tiff::encoder::colortype::Gray16>(w, h, v).unwrap();
    out.into_inner()
}

#[test]
fn every_format_round_trips() {
    let v = values();
    let raw = raw_from_bytes(&u16_bytes(&v, true), DIMS, DType::U16, true, [1.0, 2.0, 0.5], "raw").unwrap();
    assert_eq!((raw.dims, raw.values.clone()), (DIMS, v.clone()));
    for enc in ["raw", "gzip"] {
        let payload = if enc == "raw" { u16_bytes(&v, false) } else { gzip(&u16_bytes(&v, false)) };
        let n = nrrd_from_bytes(&nrrd(enc, &payload), None, "nrrd").unwrap();
        assert_eq!((n.dims, n.spacing, n.values.clone()), (DIMS, [1.0, 2.0, 0.5], v.clone()), "{enc}");
    }
    // Detached header.
    let dir = std::env::temp_dir().join(format!("voxsplat-loaders-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("data.raw"), u16_bytes(&v, false)).unwrap();
    let hdr =
        String::from_utf8(nrrd("raw", &[])).unwrap().replace("encoding: raw\n", "encoding: raw\ndata file: data.raw\n");
    let n = nrrd_from_bytes(hdr.as_bytes(), Some(&dir), "nhdr").unwrap();
    assert_eq!(n.values, v);
    for bytes in [nifti(&v), gzip(&nifti(&v))] {
        let n = nifti_from_bytes(&bytes, "nii").unwrap();
        assert_eq!((n.dims, n.spacing, n.values.clone()), (DIMS, [1.0, 2.0, 0.5], v.clone()));
    }
    let f32_data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    let (shape, got) = npy_from_bytes(&common::npy(&[4, 5, 7], "<f4", &f32_data), "npy").unwrap();
    assert_eq!((shape, got), (vec![4, 5, 7], v.clone()));
    // Raw with a TOML sidecar, through load_volume.
    std::fs::write(dir.join("vol.raw"), u16_bytes(&v, true)).unwrap();
    std::fs::write(
        dir.join("vol.raw.toml"),
        "dims = [7, 5, 4]\ndtype = \"u16\"\nendian = \"big\"\nspacing = [1.0, 2.0, 0.5]\n",
    )
    .unwrap();
    let r = crate::loaders::load_volume(&dir.join("vol.raw"), &Default::default()).unwrap();
    assert_eq!((r.dims, r.spacing, r.values.clone()), (DIMS, [1.0, 2.0, 0.5], v.clone()));
    // 16-bit PNG heights.
    let png =
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(7, 5, |x, y| image::Luma([(x * 1000 + y) as u16]));
    png.save(dir.join("h.png")).unwrap();
    let hp = crate::loaders::load_heights(&dir.join("h.png")).unwrap();
    assert_eq!((hp.width, hp.rows, hp.heights[8]), (7, 5, 1001.0));
    let hv: Vec<u16> = (0..35).map(|i| (i * 100) as u16).collect();
    let t = tiff_heights(&tiff_u16(7, 5, &hv), "tif").unwrap();
    assert_eq!((t.width, t.rows, t.heights), (7, 5, hv.iter().map(|&x| x as f32).collect::<Vec<_>>()));
}

/// ≥ 10,000 truncations and header corruptions per format: never a panic; truncations are errors.
#[test]
fn malformed_input_returns_errors() {
    let v = values();
    let f32_data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    type Parser = Box<dyn Fn(&[u8]) -> bool>;
    let formats: Vec<(&str, Vec<u8>, Parser)> = vec![
        (
            "raw",
            u16_bytes(&v, false),
            Box::new(|b| raw_from_bytes(b, DIMS, DType::U16, false, [1.0; 3], "raw").is_ok()),
        ),
        ("nrrd", nrrd("raw", &u16_bytes(&v, false)), Box::new(|b| nrrd_from_bytes(b, None, "nrrd").is_ok())),
        ("nrrd-gz", nrrd("gzip", &gzip(&u16_bytes(&v, false))), Box::new(|b| nrrd_from_bytes(b, None, "nrrd").is_ok())),
        ("nifti", nifti(&v), Box::new(|b| nifti_from_bytes(b, "nii").is_ok())),
        ("nifti-gz", gzip(&nifti(&v)), Box::new(|b| nifti_from_bytes(b, "nii").is_ok())),
        ("npy", common::npy(&[4, 5, 7], "<f4", &f32_data), Box::new(|b| npy_from_bytes(b, "npy").is_ok())),
        ("tiff", tiff_u16(7, 5, &(0..35).collect::<Vec<u16>>()), Box::new(|b| tiff_heights(b, "tif").is_ok())),
    ];
    let mut rng = Rng(2024);
    for (name, good, parse) in &formats {
        assert!(parse(good), "{name}: the valid file must load");
        let mut truncation_ok = 0;
        for it in 0..10_000 {
            let mut b = good.clone();
            if it % 2 == 0 {
                let cut = (rng.next_u64() % good.len() as u64) as usize;
                b.truncate(cut);
                if parse(&b) {
                    truncation_ok += 1;
                }
            } else {
                // Corrupt 1-4 bytes, mostly in the header.
                for _ in 0..1 + rng.next_u64() % 4 {
                    let span = if rng.f32() < 0.8 { b.len().min(400) } else { b.len() };
                    let at = (rng.next_u64() % span as u64) as usize;
                    b[at] = rng.next_u64() as u8;
                }
                let _ = parse(&b); // must return, Ok or Err, without panicking
            }
        }
        assert_eq!(truncation_ok, 0, "{name}: truncated files must not load");
    }
}

fn steep_heights() -> crate::loaders::HeightGrid {
    // Ridges with 12-level cliffs between neighbouring cells.
    let (w, rows) = (40u32, 40u32);
    let heights = (0..rows * w).map(|i| if (i % w / 5) % 2 == 0 { 0.0 } else { 12.0 } + (i / w) as f32 * 0.3).collect();
    crate::loaders::HeightGrid { width: w, rows, heights }
}

/// Pixels inside the silhouette of the voxels of `set` (ray-traced, eroded by 2 pixels) whose alpha
/// in `img` is below 0.95.
fn coverage_holes(img: &crate::ImageF32, set: &crate::SplatSet, cam: &Camera) -> usize {
    let g = set.grid();
    let inv = cam.view_proj().as_dmat4().inverse();
    let (w, h) = (img.width, img.height);
    let solid = |x: u32, y: u32| -> bool {
        let (o, d, len) = crate::truth::pixel_ray(&inv, x, y, w, h);
        let mut t = 0.0;
        while t < len {
            let p = o + d * t;
            let u = [0, 1, 2].map(|a| ((p[a] - g.origin[a] as f64) / g.spacing[a] as f64).round());
            if u.iter().all(|&c| c >= 0.0) && set.find(u[0] as u32, u[1] as u32, u[2] as u32).is_some() {
                return true;
            }
            t += 0.05;
        }
        false
    };
    let mask: Vec<bool> = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| solid(x, y)).collect();
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < w as i64 && y < h as i64 && mask[(y * w as i64 + x) as usize];
    let mut holes = 0;
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let eroded = (-2..=2).all(|dy| (-2..=2).all(|dx| inside(x + dx, y + dy)));
            if eroded && img.pixels[(y * w as i64 + x) as usize][3] < 0.95 {
                holes += 1;
            }
            if std::env::var_os("VOXSPLAT_DEBUG_HOLES").is_some() {
                let px = img.pixels[(y * w as i64 + x) as usize];
                eprint!(
                    "{}",
                    if !inside(x, y) {
                        if px[3] > 0.5 {
                            '+'
                        } else {
                            ' '
                        }
                    } else if px[3] < 0.95 {
                        'o'
                    } else {
                        '#'
                    }
                );
            }
        }
        if std::env::var_os("VOXSPLAT_DEBUG_HOLES").is_some() {
            eprintln!();
        }
    }
    holes
}

#[test]
fn terrain_columns_have_no_holes_from_a_grazing_view() {
    let heights = steep_heights();
    let filled = terrain_splats(&heights, &TerrainOptions::default()).unwrap();
    let mut r = common::cpu();
    let mut holes = Vec::new();
    for fill in [true, false] {
        let set = terrain_splats(&heights, &TerrainOptions { fill_gaps: fill, ..Default::default() }).unwrap();
        // A low view along the ridges' faces, from well outside the grid.
        let c = set.grid().center();
        let cam = Camera {
            eye: c + glam::Vec3::new(-70.0, -60.0, 10.0),
            target: c,
            up: glam::Vec3::Z,
            projection: crate::Projection::Perspective { fov_y_deg: 40.0 },
            near: 1.0,
            far: 400.0,
            width: 96,
            height: 72,
            window: None,
        };
        r.set_scene(set).unwrap();
        let img = r.render(&cam, &crate::RenderOptions::default()).unwrap().image;
        holes.push(coverage_holes(&img, &filled, &cam));
    }
    eprintln!("holes with filling {}, without {}", holes[0], holes[1]);
    assert_eq!(holes[0], 0, "filled columns leave no hole");
    assert!(holes[1] > 0, "without filling the cliffs show through");
}

fn data_present() -> bool {
    crate::loaders::data_dir().join("rmnp/rmnp-dem.tif").exists()
}

#[test]
fn flyover_breaks_btf_but_not_pbtf() {
    assert!(data_present(), "../shared/data is needed (see README)");
    let set = crate::scene::build("rmnp").unwrap();
    let mut rng = Rng(77);
    for _ in 0..6 {
        let mut cam = Camera::flyover(set.grid(), 128, 96);
        cam.eye.x += rng.range(-40.0, 40.0);
        cam.eye.y += rng.range(0.0, 60.0);
        let count = |k| {
            let o = visibility_order(&set, &cam, k, Direction::BackToFront);
            count_violations(&set, &cam, &o, Direction::BackToFront).unwrap()
        };
        let (btf, pbtf) = (count(OrderKind::Btf), count(OrderKind::Pbtf));
        assert!(btf > 0 && pbtf == 0, "btf {btf} pbtf {pbtf}");
    }
}

#[test]
fn real_presets_render_the_same_on_gpu_and_cpu() {
    assert!(data_present(), "../shared/data is needed (see README)");
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    for name in ["rmnp", "stent", "bonsai"] {
        let set = crate::scene::build(name).unwrap();
        let cam =
            if name == "rmnp" { Camera::flyover(set.grid(), 96, 72) } else { Camera::framing(set.grid(), 96, 72) };
        gpu.set_scene(set.clone()).unwrap();
        cpu.set_scene(set.clone()).unwrap();
        let o = crate::RenderOptions::default();
        let g = gpu.render(&cam, &o).unwrap().image;
        let c = cpu.render(&cam, &o).unwrap().image;
        let (max, mean) = common::assert_mirrors(&g, &c, name);
        eprintln!("{name}: {} splats, max |diff| {max:.2e}, mean over covered {mean:.2e}", set.len());
        assert!(g.pixels.iter().filter(|p| p[3] > 0.3).count() > 200, "{name} is visible");
    }
    common::assert_clean(&gpu);
}

#[test]
fn transfer_functions_are_checked() {
    use crate::classify::TransferFunction;
    let tf =
        TransferFunction::from_toml("points = [[0.2, [1.0, 0.0, 0.0, 0.0]], [0.8, [1.0, 1.0, 1.0, 0.5]]]").unwrap();
    assert_eq!(tf.eval(0.5), [1.0, 0.5, 0.5, 0.25]);
    for bad in [
        "points = []",
        "points = [[0.8, [1.0, 1.0, 1.0, 0.5]], [0.2, [1.0, 0.0, 0.0, 0.0]]]",
        "points = [[0.2, [1.0, 0.0, 0.0, 1.5]]]",
        "points = [[0.2, [1.0, 0.0, 0.0, 0.5]]]\ngradient_weight = -1",
        "pointz = 3",
    ] {
        assert!(TransferFunction::from_toml(bad).is_err(), "accepted {bad}");
    }
    assert!(TransferFunction::preset("nope").is_err());
    // The extraction threshold removes voxels the ramp would keep.
    let vol = crate::loaders::ScalarVolume { dims: [4, 1, 1], spacing: [1.0; 3], values: vec![0.0, 1.0, 2.0, 3.0] };
    let ramp =
        TransferFunction::from_toml("points = [[0.0, [1.0, 1.0, 1.0, 0.0]], [1.0, [1.0, 1.0, 1.0, 1.0]]]").unwrap();
    assert_eq!(crate::classify::classify(&vol, &ramp, None).unwrap().len(), 3);
    let cut = TransferFunction { threshold: 0.5, ..ramp };
    assert_eq!(crate::classify::classify(&vol, &cut, None).unwrap().len(), 2);
}

/// An absolute accuracy bound on the real datasets: the default GPU frame against the ray-cast
/// truth (CPU, 0.25-voxel steps, trilinear), at most 1.2x the RMSE measured when the ceilings were
/// set (2026-11-24; frames repeat bit for bit), so a change that degrades real pictures fails here.
#[test]
fn real_scenes_stay_within_their_error_ceilings() {
    assert!(data_present(), "../shared/data is needed (see README)");
    let mut gpu = common::gpu();
    let mut cpu = common::cpu();
    // The bonsai preset as it was when the ceilings were set (issue 29 made the base plate
    // transparent and the trunk and pot opaque): its ceiling keeps guarding the same picture.
    let before = crate::classify::TransferFunction {
        points: vec![
            (0.0, [0.0, 0.0, 0.0, 0.0]),
            (0.15, [0.0, 0.0, 0.0, 0.0]),
            (0.25, [0.25, 0.6, 0.15, 0.35]),
            (0.45, [0.3, 0.55, 0.15, 0.6]),
            (0.6, [0.55, 0.35, 0.15, 0.9]),
            (1.0, [0.7, 0.5, 0.3, 0.95]),
        ],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    };
    let bonsai =
        crate::loaders::load_volume(&crate::loaders::data_dir().join("bonsai/bonsai.nii.gz"), &Default::default())
            .unwrap();
    let scenes = [
        ("bonsai", CEILING_BONSAI),
        ("bonsai (preset before issue 29)", CEILING_BONSAI_BEFORE),
        ("stent", CEILING_STENT),
        ("rmnp", CEILING_RMNP),
    ];
    for (name, ceiling) in scenes {
        let set = match name {
            "bonsai (preset before issue 29)" => crate::classify::classify(&bonsai, &before, None).unwrap(),
            _ => crate::scene::build(name).unwrap(),
        };
        let cam =
            if name == "rmnp" { Camera::flyover(set.grid(), 96, 72) } else { Camera::framing(set.grid(), 96, 72) };
        gpu.set_scene(set.clone()).unwrap();
        cpu.set_scene(set).unwrap();
        let truth = cpu.raycast(&cam, &RaycastOptions { step: 0.25, ..Default::default() }).unwrap().image;
        let frame = gpu.render(&cam, &crate::RenderOptions::default()).unwrap().image;
        let rmse = crate::metrics::compare(&frame, &truth).unwrap().rmse;
        eprintln!("{name}: RMSE {rmse:.6} against the ray-cast truth (ceiling {ceiling})");
        assert!(common::covered(&frame) > 96 * 72 / 20, "{name} is drawn");
        assert!(rmse <= ceiling, "{name}: RMSE {rmse} against the ray-cast truth, ceiling {ceiling}");
    }
    common::assert_clean(&gpu);
}
/// 1.2x the measured 0.006291 (bonsai, the preset before issue 29), 0.013236 and 0.040137; the
/// bonsai preset of issue 29: 1.2x the measured 0.010381 (2026-11-24).
const CEILING_BONSAI_BEFORE: f64 = 0.00755;
const CEILING_BONSAI: f64 = 0.01246;
const CEILING_STENT: f64 = 0.0159;
const CEILING_RMNP: f64 = 0.0482;
