//! Issue 25: input a hostile user would try, each a typed error or a right picture, never a hang,
//! a wrap-around or a silently wrong frame (the CLI's side: cli/tests/hostile.rs).
use super::common;
use crate::bricks::{BrickScene, BrickStore};
use crate::classify::TransferFunction;
use crate::loaders::{load_volume, npy_from_bytes, DType, VolumeHints};
use crate::volume::ScalarVolume;
use crate::RaycastOptions;
use crate::{Camera, Error, Grid, ImageF32, Projection, Raster, RenderOptions};
use common::{assert_clean, cpu, gpu};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("voxsplat-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn covered(img: &ImageF32) -> usize {
    img.pixels.iter().filter(|p| p[3] > 0.01).count()
}

#[test]
fn loaders_read_only_what_the_header_or_dims_need() {
    let hints = VolumeHints { dims: Some([16, 16, 16]), dtype: Some(DType::U8), ..Default::default() };
    // A device that never ends is refused from its length, not read until memory runs out.
    let e = load_volume(Path::new("/dev/zero"), &hints).unwrap_err();
    assert!(e.to_string().contains("needs 4096"), "{e}");
    // A sparse file far longer than --dims says: refused before a byte is read.
    let big = dir().join("sparse.raw");
    std::fs::File::create(&big).unwrap().set_len(1 << 31).unwrap();
    let e = load_volume(&big, &hints).unwrap_err();
    assert!(e.to_string().contains("has 2147483648 bytes"), "{e}");
    std::fs::remove_file(&big).unwrap();
    // An NRRD whose data is followed by a 2 GiB tail loads its data and leaves the tail unread.
    let tail = dir().join("tail.nrrd");
    let mut bytes = b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 2 2\nencoding: raw\n\n".to_vec();
    bytes.extend((0u8..16).map(|i| i * 3));
    std::fs::write(&tail, &bytes).unwrap();
    std::fs::OpenOptions::new().write(true).open(&tail).unwrap().set_len(1 << 31).unwrap();
    let v = load_volume(&tail, &VolumeHints::default()).unwrap();
    assert_eq!(v.values, (0..16).map(|i| (i * 3) as f32).collect::<Vec<_>>());
    std::fs::remove_file(&tail).unwrap();
    // An npy whose header promises more than the file holds.
    let npy = common::npy(&[64, 64, 64], "|u1", &[7u8; 64]);
    let short = dir().join("short.npy");
    std::fs::write(&short, &npy).unwrap();
    let e = load_volume(&short, &VolumeHints::default()).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
    // Dims, type and byte order describe raw files: given for a file with a header, refused.
    std::fs::write(&tail, &bytes).unwrap();
    let e = load_volume(&tail, &VolumeHints { big_endian: true, ..Default::default() }).unwrap_err();
    assert!(e.to_string().contains("describe raw files"), "{e}");
}

#[test]
fn non_finite_samples_and_spacings_are_errors_in_every_format() {
    // An all-NaN npy (it reported "values 1 .. 1").
    let nan: Vec<u8> = (0..8).flat_map(|_| f32::NAN.to_le_bytes()).collect();
    let e = npy_from_bytes(&common::npy(&[2, 2, 2], "<f4", &nan), "nan.npy").unwrap_err();
    assert!(e.to_string().contains("must be finite"), "{e}");
    let raw = dir().join("inf.raw");
    let mut v: Vec<u8> = (0..8).flat_map(|i| (i as f32).to_le_bytes()).collect();
    v[12..16].copy_from_slice(&f32::INFINITY.to_le_bytes());
    std::fs::write(&raw, &v).unwrap();
    let hints = VolumeHints { dims: Some([2, 2, 2]), dtype: Some(DType::F32), ..Default::default() };
    let e = load_volume(&raw, &hints).unwrap_err();
    assert!(e.to_string().contains("sample 3 is inf"), "{e}");
    // NIfTI: a scl_slope that overflows f32 (it dropped 97 % of the splats), pixdim NaN or 0 (it
    // became 1), and a negative dim (it said "more than 268435456 voxels").
    let nifti = |edit: &dyn Fn(&mut Vec<u8>)| {
        let mut h = vec![0u8; 352];
        h[0..4].copy_from_slice(&348i32.to_le_bytes());
        for (i, d) in [3i16, 2, 2, 2, 1, 1, 1, 1].iter().enumerate() {
            h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
        }
        h[70..72].copy_from_slice(&2i16.to_le_bytes()); // uint8
        h[72..74].copy_from_slice(&8i16.to_le_bytes());
        for i in 0..8 {
            h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
        }
        h[108..112].copy_from_slice(&352f32.to_le_bytes());
        h[112..116].copy_from_slice(&1f32.to_le_bytes());
        h[344..348].copy_from_slice(b"n+1\0");
        h.extend_from_slice(&[0, 50, 100, 150, 200, 250, 255, 1]);
        edit(&mut h);
        let path = dir().join("edit.nii");
        std::fs::write(&path, &h).unwrap();
        load_volume(&path, &VolumeHints::default())
    };
    assert!(nifti(&|_| {}).is_ok());
    let e = nifti(&|h| h[112..116].copy_from_slice(&3e38f32.to_le_bytes())).unwrap_err();
    assert!(e.to_string().contains("is inf"), "{e}");
    for p in [f32::NAN, 0.0] {
        let e = nifti(&|h| h[80..84].copy_from_slice(&p.to_le_bytes())).unwrap_err();
        assert!(e.to_string().contains("pixdim[1]"), "{e}");
    }
    let e = nifti(&|h| h[42..44].copy_from_slice(&(-256i16).to_le_bytes())).unwrap_err();
    assert!(e.to_string().contains("dim[1] = -256"), "{e}");
}

#[test]
fn full_disks_fail_writes_instead_of_leaving_short_files() {
    let img = ImageF32 { width: 96, height: 64, pixels: vec![[0.2, 0.3, 0.4, 0.5]; 96 * 64] };
    for name in ["full.png", "full.exr"] {
        let link = dir().join(name);
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink("/dev/full", &link).unwrap();
        let e = crate::output::write_image(&img, &link).unwrap_err();
        assert!(e.to_string().contains("No space left"), "{name}: {e}");
    }
    let mut gif = crate::output::GifWriter::create(Path::new("/dev/full"), 80).unwrap();
    let pushed = gif.push(&img).and_then(|_| gif.push(&img));
    assert!(pushed.is_err() || gif.finish().is_err(), "a GIF on a full disk must fail");
    // A good GIF streams and reads back with its frames.
    let path = dir().join("ok.gif");
    let mut gif = crate::output::GifWriter::create(&path, 80).unwrap();
    for _ in 0..3 {
        gif.push(&img).unwrap();
    }
    gif.finish().unwrap();
    use image::AnimationDecoder as _;
    let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()))
        .unwrap()
        .into_frames()
        .count();
    assert_eq!(frames, 3);
}

/// An opaque one-voxel volume: every splat path draws it (the framing view put the eye inside the
/// near-plane cull, and the store dropped a constant volume's only value as background).
#[test]
fn a_one_voxel_volume_is_drawn_by_every_path() {
    let vol = ScalarVolume { dims: [1, 1, 1], spacing: [1.0; 3], values: vec![200.0] };
    let tf = TransferFunction::from_toml(
        "points = [[0.0, [1.0, 1.0, 1.0, 1.0]], [1.0, [1.0, 1.0, 1.0, 1.0]]]\nrange = [0.0, 255.0]",
    )
    .unwrap();
    let cam = Camera::framing(&Grid::centered(vol.dims, vol.spacing).unwrap(), 64, 48);
    let mut reference = cpu();
    let splats = crate::classify::classify(&vol, &tf, None).unwrap();
    reference.set_scene(splats.clone()).unwrap();
    let truth = covered(&reference.raycast(&cam, &RaycastOptions::default()).unwrap().image);
    assert!(truth > 500, "the ray caster covers {truth} px");
    for raster in [Raster::Graphics, Raster::Compute, Raster::Points] {
        for mut r in [gpu(), cpu()] {
            let mut o = RenderOptions::default();
            o.raster = raster;
            r.set_scene(splats.clone()).unwrap();
            let dense = covered(&r.render(&cam, &o).unwrap().image);
            r.set_bricks(BrickScene::new(BrickStore::build(&vol).unwrap(), tf.clone(), None).unwrap()).unwrap();
            let bricked = covered(&r.render(&cam, &o).unwrap().image);
            for (what, n) in [("dense", dense), ("bricked", bricked)] {
                // The kernel's footprint is wider than the trilinear voxel's: drawn, not blank.
                assert!(n * 4 > truth && n < truth * 4, "{raster:?} {what}: {n} px against the ray caster's {truth}");
            }
            assert_clean(&r);
        }
    }
}

#[test]
fn the_ray_casters_refuse_rays_max_steps_would_cut() {
    // The mirror stopped at max_steps and drew an almost transparent picture; the GPU names its
    // own loop budget first.
    for (mut r, says) in [(cpu(), "max_steps"), (gpu(), "the GPU ray caster takes at most")] {
        let set = crate::scene::build("cube60").unwrap();
        let cam = Camera::framing(set.grid(), 32, 32);
        r.set_scene(set).unwrap();
        let e = r.raycast(&cam, &RaycastOptions { step: 1e-6, ..Default::default() }).unwrap_err();
        assert!(matches!(e, Error::TooLarge(_)) && e.to_string().contains(says), "{e}");
        assert!(r.raycast(&cam, &RaycastOptions::default()).is_ok());
    }
}

#[test]
fn views_f32_cannot_resolve_are_refused() {
    let grid = Grid::centered([60, 60, 60], [1.0; 3]).unwrap();
    let base = Camera::framing(&grid, 64, 64);
    for h in [1e-7f32, 1e-20, 1e-30] {
        let cam = Camera { projection: Projection::Orthographic { height: h }, ..base };
        let e = cam.validate().unwrap_err();
        assert!(e.to_string().contains("f32 cannot resolve"), "{h}: {e}");
    }
    assert!(Camera { projection: Projection::Orthographic { height: 0.5 }, ..base }.validate().is_ok());
    let far = Camera { eye: glam::Vec3::new(0.0, 0.0, 1e30), ..base };
    assert!(far.validate().unwrap_err().to_string().contains("within 1e15"));
    let telephoto = Camera { projection: Projection::Perspective { fov_y_deg: 1e-9 }, ..base };
    assert!(telephoto.validate().is_err());
}

#[test]
fn an_animation_path_is_checked_before_any_frame() {
    let text = r#"
scene = "cube40"
frames = 10
[camera]
eye = [0.0, 0.0, 100.0]
target = [0.0, 0.0, 0.0]
[[keyframe]]
frame = 0
eye = [0.0, 0.0, 100.0]
target = [0.0, 0.0, 0.0]
[[keyframe]]
frame = 8
eye = [0.0, 0.0, -100.0]
target = [0.0, 0.0, 0.0]
"#;
    let anim = crate::animate::Animation::from_toml(text).unwrap();
    let grid = *crate::scene::build("cube40").unwrap().grid();
    let e = anim.check_path(&grid, crate::animate::Blur::None).unwrap_err();
    assert!(matches!(e, Error::InvalidCamera(_)) && e.to_string().contains("frame 4"), "{e}");
}

#[test]
fn terrain_levels_and_messages_do_not_wrap() {
    let h = crate::volume::HeightGrid { width: 4, rows: 4, heights: (0..16).map(|i| i as f32).collect() };
    let opts = crate::terrain::TerrainOptions { vscale: 1e30, ..Default::default() };
    let e = crate::terrain::terrain_splats(&h, &opts).unwrap_err();
    assert!(matches!(e, Error::TooLarge(_)), "{e}");
    // A corrupt TIFF's decoder message is cut to a readable length.
    let mut tiff = std::io::Cursor::new(Vec::new());
    tiff::encoder::TiffEncoder::new(&mut tiff)
        .unwrap()
        .write_image::<tiff::encoder::colortype::Gray16>(64, 64, &[7u16; 64 * 64])
        .unwrap();
    let good = tiff.into_inner();
    let mut longest = 0;
    for i in 0..good.len().min(400) {
        for bit in 0..8 {
            let mut b = good.clone();
            b[i] ^= 1 << bit;
            if let Err(e) = crate::loaders::tiff_heights(&b, "flip.tif") {
                longest = longest.max(e.to_string().len());
            }
        }
    }
    assert!(longest > 0 && longest < 600, "longest message {longest} bytes");
    // Reading a missing or broken image says so (it said "cannot write image").
    let bad = dir().join("broken.png");
    std::fs::write(&bad, b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let e = crate::output::read_image(&bad).unwrap_err();
    assert!(e.to_string().starts_with("cannot read image"), "{e}");
}

#[test]
fn banded_ssim_is_the_whole_image_ssim() {
    let mut rng = common::Rng(7);
    let (w, h) = (150usize, 133usize);
    let img = |rng: &mut common::Rng| ImageF32 {
        width: w as u32,
        height: h as u32,
        pixels: (0..w * h).map(|_| [rng.f32(), rng.f32(), rng.f32(), rng.f32()]).collect(),
    };
    let (a, b) = (img(&mut rng), img(&mut rng));
    let m = crate::metrics::compare(&a, &b).unwrap();
    let alpha = |im: &ImageF32| im.pixels.iter().map(|p| p[3].clamp(0.0, 1.0) as f64).collect::<Vec<_>>();
    let whole = crate::metrics::ssim(&alpha(&a), &alpha(&b), w, h);
    assert!((m.ssim_alpha - whole).abs() < 1e-12, "{} against {whole}", m.ssim_alpha);
}

/// Issue 44: a transfer function's points and range take exactly the components they name; a
/// colour of five, a point or a range of three elements is refused, not cut short.
#[test]
fn transfer_function_points_take_no_extra_components() {
    let ok = TransferFunction::from_toml("points = [[0.1, [0, 0, 0, 0]], [1.0, [1, 1, 1, 0.5]]]\nrange = [0.0, 2.0]")
        .unwrap();
    assert_eq!(ok.points[1], (1.0, [1.0, 1.0, 1.0, 0.5]));
    assert_eq!(ok.range, Some((0.0, 2.0)));
    for (text, needle) in [
        ("points = [[0.1, [0, 0, 0, 0, 0]]]", "4 components"),
        ("points = [[0.1, [0, 0, 0]]]", "4 components"),
        ("points = [[0.1, [0, 0, 0, 0], 3]]", "a point [density"),
        ("points = [[0.1]]", "a point [density"),
        ("points = [[0.1, [0, 0, 0, 0]]]\nrange = [0.0, 1.0, 2.0]", "a range [low, high]"),
    ] {
        let e = TransferFunction::from_toml(text).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)) && e.to_string().contains(needle), "{text}: {e}");
    }
}

/// Issue 44: a transfer-function or animation file past `MAX_TEXT_BYTES` is refused from its
/// length, before a byte of it is parsed (a 2 M-point file took 3.2 GB and 10 s to be refused).
#[test]
fn text_files_are_refused_past_their_size_cap() {
    use crate::loaders::{read_text, MAX_TEXT_BYTES};
    let big = dir().join("big-tf.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(MAX_TEXT_BYTES + 1).unwrap();
    let t = std::time::Instant::now();
    let e = read_text(&big, "big-tf.toml").unwrap_err();
    assert!(matches!(e, Error::TooLarge(_)) && e.to_string().contains("more than"), "{e}");
    assert!(t.elapsed().as_secs_f64() < 1.0);
    let bad = dir().join("latin1.toml");
    std::fs::write(&bad, b"points = [[0.1, [0, 0, 0, 0]]] # caf\xe9").unwrap();
    assert!(read_text(&bad, "latin1.toml").unwrap_err().to_string().contains("UTF-8"));
}

/// Issue 44: a file name that is not UTF-8 keeps its extension: an NRRD is read as NRRD, not
/// taken for raw data ("needs --dims").
#[test]
fn a_file_name_that_is_not_utf8_is_read_by_its_extension() {
    use std::os::unix::ffi::OsStrExt;
    let head = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n\n";
    let mut bytes = head.as_bytes().to_vec();
    bytes.extend((0..24).map(|i| i as u8));
    let p = dir().join(std::ffi::OsStr::from_bytes(b"caf\xe9.nrrd"));
    std::fs::write(&p, &bytes).unwrap();
    let v = load_volume(&p, &VolumeHints::default()).unwrap();
    assert_eq!(v.dims, [2, 3, 4]);
    assert_eq!(v.values[23], 23.0);
}

/// Issue 44: NRRD fields that move or split the data are refused by name, not read past: `byte
/// skip` and `line skip` (the skipped bytes were read as data), `data file: LIST`, and an `endian`
/// other than little or big. Through both readers: the whole-file one and the streamed slices.
#[test]
fn nrrd_skips_lists_and_odd_endians_are_refused_by_name() {
    let body = |extra: &str| {
        let mut b =
            format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n{extra}\n\n").into_bytes();
        b.extend_from_slice(&[7; 16]);
        b
    };
    for (extra, needle) in [
        ("byte skip: 8", "byte skip: 8"),
        ("byte skip: -1", "byte skip: -1"),
        ("line skip: 2", "line skip: 2"),
        ("data file: LIST", "names several data files"),
        ("data file: slice%03d.raw 0 9 1", "names several data files"),
        ("endian: middle", "little or big"),
    ] {
        let p = dir().join(format!("skip-{}.nrrd", extra.replace([' ', ':', '%'], "_")));
        std::fs::write(&p, body(extra)).unwrap();
        let e = load_volume(&p, &VolumeHints::default()).unwrap_err();
        assert!(e.to_string().contains(needle), "{extra}: {e}");
        let e = crate::loaders::SliceReader::open(&p, &VolumeHints::default()).map(|_| ()).unwrap_err();
        assert!(e.to_string().contains(needle), "{extra} (streamed): {e}");
    }
    // A zero skip is the default, and read as such.
    let p = dir().join("skip-zero.nrrd");
    std::fs::write(&p, body("byte skip: 0\nline skip: 0")).unwrap();
    assert_eq!(load_volume(&p, &VolumeHints::default()).unwrap().values, vec![7.0; 8]);
}

/// Issue 44: a float volume whose range spans more than f32's largest value (max − min
/// overflowed to infinity: every voxel normalised to 0) is drawn, dense and bricked, on the GPU
/// and the mirrors; so is a TF range as wide.
#[test]
fn ranges_wider_than_f32_normalise_in_f64() {
    let mut values = vec![-1e38f32; 27];
    values[13] = 3e38;
    let vol = ScalarVolume { dims: [3, 3, 3], spacing: [1.0; 3], values };
    // Opaque only at the top of the range: the one hot voxel.
    let tf = TransferFunction::from_toml("points = [[0.0, [0, 0, 0, 0]], [0.9, [0, 0, 0, 0]], [1.0, [1, 1, 1, 1]]]")
        .unwrap();
    let cam = Camera::framing(&Grid::centered(vol.dims, vol.spacing).unwrap(), 48, 48);
    let splats = crate::classify::classify(&vol, &tf, None).unwrap();
    assert_eq!(splats.len(), 1, "the hot voxel, classified");
    for mut r in [gpu(), cpu()] {
        r.set_scene(splats.clone()).unwrap();
        assert!(covered(&r.render(&cam, &RenderOptions::default()).unwrap().image) > 20);
        r.set_bricks(BrickScene::new(BrickStore::build(&vol).unwrap(), tf.clone(), None).unwrap()).unwrap();
        let bricked = r.render(&cam, &RenderOptions::default()).unwrap();
        assert_eq!(bricked.stats.splats, 1, "{:?}", bricked.stats);
        assert!(covered(&bricked.image) > 20);
        assert_clean(&r);
    }
    // A TF range of [-3e38, 3e38] over ordinary values: they sit at its middle, drawn.
    let ordinary = ScalarVolume { dims: [3, 3, 3], spacing: [1.0; 3], values: vec![5.0; 27] };
    let wide = TransferFunction::from_toml("points = [[0.0, [0, 0, 0, 0]], [0.4, [0, 0, 0, 0]], [0.5, [1, 1, 1, 1]], [1.0, [1, 1, 1, 1]]]\nrange = [-3e38, 3e38]").unwrap();
    let set = crate::classify::classify(&ordinary, &wide, None).unwrap();
    assert_eq!(set.len(), 27);
    let mut r = cpu();
    r.set_bricks(BrickScene::new(BrickStore::build(&ordinary).unwrap(), wide, None).unwrap()).unwrap();
    assert!(covered(&r.render(&cam, &RenderOptions::default()).unwrap().image) > 100);
}

/// Issue 44: a keyframe's rotation axis of 1e30 (its f32 length overflows) turns the object as
/// the unit axis does; it was dropped, the frames standing still.
#[test]
fn a_huge_rotation_axis_keeps_its_direction() {
    let anim = |axis: &str| {
        let text = format!(
            "scene = \"cube40\"\nframes = 9\n[camera]\neye = [0.0, 0.0, 100.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[keyframe]]\nframe = 0\nrotate = [{axis}, 0.0]\n[[keyframe]]\nframe = 8\nrotate = [{axis}, 90.0]\n"
        );
        crate::animate::Animation::from_toml(&text).unwrap()
    };
    let grid = *crate::scene::build("cube40").unwrap().grid();
    let (huge, unit) = (anim("1e30, 0.0, 0.0"), anim("1.0, 0.0, 0.0"));
    for t in [0.0, 2.0, 4.0, 8.0] {
        let (a, b) = (huge.model(&grid, t), unit.model(&grid, t));
        assert!(a.abs_diff_eq(b, 1e-5), "t {t}: {a:?} against {b:?}");
    }
    assert!(!huge.model(&grid, 4.0).abs_diff_eq(huge.model(&grid, 0.0), 1e-3), "frame 4 turns");
}

/// Issue 44: messages that name the real cause. A NIfTI-2 file ("Invalid NIfTI-1 file"), an npy of
/// uint64 ("Uint8"), an NRRD header longer than 1 MiB ("no type field" from the streamed reader),
/// a spacing of 1e30 (an invalid camera later on), a clipping plane whose normal is 1e30 long (a
/// direction: "normal must be finite" before).
#[test]
fn refusals_name_the_real_cause() {
    let mut two = vec![0u8; 560];
    two[..4].copy_from_slice(&540u32.to_le_bytes());
    two[4..8].copy_from_slice(b"n+2\0");
    let p = dir().join("two.nii");
    std::fs::write(&p, &two).unwrap();
    let e = load_volume(&p, &VolumeHints::default()).unwrap_err();
    assert!(matches!(e, Error::Unsupported(_)) && e.to_string().contains("NIfTI-2"), "{e}");
    let e = npy_from_bytes(&common::npy(&[2, 2, 2], "<u8", &[0u8; 64]), "u64.npy").unwrap_err();
    assert!(e.to_string().contains("uint64") && e.to_string().contains("float32"), "{e}");
    let mut long = b"NRRD0004\ntype: uint8\n".to_vec();
    long.extend(std::iter::repeat_n(b"# comment\n".iter().copied(), 120_000).flatten());
    long.extend_from_slice(b"dimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    long.extend_from_slice(&[1; 8]);
    let p = dir().join("long-comment.nrrd");
    std::fs::write(&p, &long).unwrap();
    let e = load_volume(&p, &VolumeHints::default()).unwrap_err();
    assert!(e.to_string().contains("longer than 1 MiB"), "{e}");
    let e = crate::loaders::SliceReader::open(&p, &VolumeHints::default()).map(|_| ()).unwrap_err();
    assert!(e.to_string().contains("longer than 1 MiB"), "streamed: {e}");
    let p = dir().join("huge-spacing.nrrd");
    let mut b = b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1e30 1 1\nencoding: raw\n\n".to_vec();
    b.extend_from_slice(&[1; 8]);
    std::fs::write(&p, &b).unwrap();
    let e = load_volume(&p, &VolumeHints::default()).unwrap_err();
    assert!(e.to_string().contains("past 1e10 units a voxel"), "{e}");
    crate::Clip::new(&[glam::Vec4::new(1e30, 0.0, 0.0, 0.0)], None).unwrap();
    assert!(crate::Clip::new(&[glam::Vec4::new(0.0, 0.0, 0.0, 1.0)], None).is_err());
}

/// Issue 44: a splat blur takes one path and one profile; `splat:arc+slotted+tapered+teardrop`
/// kept the last profile silently.
#[test]
fn a_blur_takes_one_path_and_one_profile() {
    use crate::animate::Blur;
    for bad in ["splat:arc+slotted+tapered+teardrop", "splat:tapered+teardrop", "splat:arc+line"] {
        let e = bad.parse::<Blur>().unwrap_err();
        assert!(e.to_string().contains("both given"), "{bad}: {e}");
    }
    for good in ["splat", "splat:arc", "splat:arc+tapered", "splat:teardrop+line", "none", "accum:4"] {
        good.parse::<Blur>().unwrap();
    }
}

/// Issue 44: a classified set past the GPU path's splat cap is refused for splat frames only; the
/// ray caster, which draws no splats, casts it on the device (it refused the set outright).
#[test]
fn a_set_past_the_splat_cap_is_still_ray_cast() {
    let n = 150; // 3,375,000 voxels, past MAX_GPU_SPLATS
    assert!(n * n * n > crate::constants::MAX_GPU_SPLATS);
    let grid = Grid::centered([n; 3], [1.0; 3]).unwrap();
    let set = crate::SplatSet::from_fn(grid, |_, _, _| Some([0.8, 0.6, 0.4, 0.02])).unwrap();
    let cam = Camera::framing(&grid, 24, 24);
    let mut g = gpu();
    g.set_scene(set).unwrap();
    let e = g.render(&cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(e, Error::TooLarge(_)) && e.to_string().contains("cast rays"), "{e}");
    let image = g.raycast(&cam, &RaycastOptions { step: 1.0, ..Default::default() }).unwrap().image;
    assert!(covered(&image) > 24 * 24 / 4, "the ray cast drew {} pixels", covered(&image));
    assert_clean(&g);
}

/// Issue 44: with no budget set, the host budget is three quarters of physical memory (it was
/// only what the host had available, so one request could take the machine's last free byte).
#[test]
fn the_host_budget_defaults_to_a_share_of_physical_memory() {
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap();
    let kb = |field: &str| -> u64 {
        let line = meminfo.lines().find(|l| l.starts_with(field)).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let total = kb("MemTotal:") * 1024;
    assert_eq!(crate::options::host_budget(), Some(total / 4 * 3));
    // A gzip stream allowed to inflate to 90 % of physical memory: refused before a byte is read.
    let e = crate::loaders::gunzip(&[], total / 10 * 9, "a test's stream").unwrap_err();
    assert!(e.to_string().contains("past the host budget") && e.to_string().contains("three quarters"), "{e}");
}

/// Issue 44, found by fuzzing (fuzz/seeds/npy/found-oom-f5235dbe...): an `.npy` read from bytes whose
/// version-3 header length says 3.6 GB made npyz allocate that before reading a byte; the length is
/// checked against the bytes first, as the file path checks it.
#[test]
fn an_npy_header_length_past_its_bytes_is_refused_before_allocating() {
    let mut bytes = b"\x93NUMPY\x03\x00".to_vec();
    bytes.extend_from_slice(&0xd97b_0076u32.to_le_bytes());
    bytes.extend_from_slice(b"{'descr': '<i2', 'fortran_order': False, 'shape': (2, 2), }");
    let e = npy_from_bytes(&bytes, "bomb.npy").unwrap_err();
    assert!(e.to_string().contains("npy: a header of"), "{e}");
    // A header that ends inside the bytes still reads.
    let ok = common::npy(&[2, 2], "<i2", &[1, 0, 2, 0, 3, 0, 4, 0]);
    assert_eq!(npy_from_bytes(&ok, "ok.npy").unwrap().1, vec![1.0, 2.0, 3.0, 4.0]);
}

/// Issue 44, found by fuzzing: npyz parses an `.npy` header with a general Python-literal grammar
/// that backtracks exponentially with nesting (12 nested braces: 1 s; the fuzzer's 4 KB header ran
/// for over 20 minutes). Headers are checked first against the plain dict numpy writes.
#[test]
fn an_npy_header_that_is_not_numpy_s_dict_is_refused_before_it_is_parsed() {
    for (header, needle) in [
        (format!("{{'descr': {}1.5", "{".repeat(40)), "nested deeper"),
        ("{'descr': '<f4', 'fortran_order': False, 'shape': [2, 2], }".to_string(), "'['"),
        ("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), } \x7f".to_string(), "\\x7f"),
        // npyz multiplies the shape out unchecked (a panic in a debug build).
        (
            "{'descr': '>f8', 'fortran_order': False, 'shape': (23333333333333333,333333, 3, 2), }".to_string(),
            "overflows",
        ),
    ] {
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        let e = npy_from_bytes(&bytes, "odd.npy").unwrap_err();
        assert!(e.to_string().contains(needle), "{header:?}: {e}");
        // Read from a file (a volume, or terrain heights), the whole header is checked too.
        let path = dir().join("odd.npy");
        std::fs::write(&path, &bytes).unwrap();
        let e = crate::loaders::load_heights(&path).unwrap_err();
        assert!(e.to_string().contains(needle), "{header:?}: {e}");
        let e = load_volume(&path, &VolumeHints::default()).unwrap_err();
        assert!(e.to_string().contains(needle), "{header:?}: {e}");
    }
}
