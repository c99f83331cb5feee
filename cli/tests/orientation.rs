//! Named anatomical views from the file's placement (issue 29): superior up whichever way the file
//! stores its slices, a clear error for views of data without a frame, and the orientation code.
use crate::cmd;
use crate::common;
use cmd::voxsplat;
use common::{nifti, DIMS};
use glam::{DMat4, DVec3, DVec4};

fn tmp(name: &str) -> std::path::PathBuf {
    cmd::tmp_in("orientation", name)
}

fn affine(cols: [DVec3; 3], t: DVec3) -> DMat4 {
    DMat4::from_cols(cols[0].extend(0.0), cols[1].extend(0.0), cols[2].extend(0.0), DVec4::new(t.x, t.y, t.z, 1.0))
}

/// A "T": a slab across the superior end (k 12..14) on a thin column. Stored with superior at high
/// k (RAS), and stored upside down with the affine flipped along k (superior at low k: RAI, a
/// left-handed file). Each test passes its own `tag`: tests run in parallel, and one rewriting a
/// file another is reading hands it a truncated volume.
fn files(tag: &str) -> [std::path::PathBuf; 2] {
    let tee =
        |i: u32, j: u32, k: u32| ((12..=14).contains(&k) || (5..=6).contains(&i) && (4..=5).contains(&j)) as u8 * 200;
    let [nx, ny, nz] = DIMS;
    let stored = |flip: bool| {
        let mut v = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    v.push(tee(i, j, if flip { nz - 1 - k } else { k }));
                }
            }
        }
        v
    };
    let up = nifti(DIMS, &stored(false), Some(affine([DVec3::X, DVec3::Y, DVec3::Z], DVec3::ZERO)), None);
    let t = DVec3::Z * (nz - 1) as f64;
    let down = nifti(DIMS, &stored(true), Some(affine([DVec3::X, DVec3::Y, -DVec3::Z], t)), None);
    let (a, b) = (tmp(&format!("{tag}-ras.nii")), tmp(&format!("{tag}-rai.nii")));
    std::fs::write(&a, up).unwrap();
    std::fs::write(&b, down).unwrap();
    [a, b]
}

fn render(file: &std::path::Path, view: &str, out: &str) -> image::RgbaImage {
    render_with(file, view, out, &[])
}

fn render_with(file: &std::path::Path, view: &str, out: &str, extra: &[&str]) -> image::RgbaImage {
    let path = tmp(out);
    let mut args = vec![
        "render",
        "--volume",
        file.to_str().unwrap(),
        "--tf",
        "ramp",
        "--view",
        view,
        "--size",
        "64x64",
        "--validation",
        "--out",
        path.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = voxsplat(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    image::open(&path).unwrap().to_rgba8()
}

/// Mean row of the drawn pixels, weighted by opacity (0 = top).
fn mean_row(img: &image::RgbaImage) -> f64 {
    let (mut s, mut w) = (0.0, 0.0);
    for (_, y, p) in img.enumerate_pixels() {
        s += y as f64 * p[3] as f64;
        w += p[3] as f64;
    }
    assert!(w > 0.0, "something drawn");
    s / w
}

#[test]
fn a_flipped_affine_renders_the_same_way_up() {
    let [up, down] = files("views");
    for view in ["anterior", "oblique", "left", "superior"] {
        let (a, b) = (render(&up, view, &format!("up-{view}.png")), render(&down, view, &format!("down-{view}.png")));
        // The two grids are drawn in different (both valid) visibility orders: rounding apart.
        let d: Vec<u8> =
            a.pixels().zip(b.pixels()).map(|(p, q)| (0..4).map(|c| p[c].abs_diff(q[c])).max().unwrap()).collect();
        let (max, over) = (d.iter().max().copied().unwrap_or(0), d.iter().filter(|&&x| x > 2).count());
        assert!(max <= 8 && over <= 16, "{view}: the two files draw alike (largest difference {max}/255, {over} px)");
        if view != "superior" {
            // Superior up: the slab, most of the T, is drawn in the upper half.
            let row = mean_row(&a);
            assert!(row < 26.0, "{view}: the T's slab is drawn high, mean row {row} of 64");
        }
    }
    // Without the frame the upside-down file draws upside down (today's default view).
    let (a, b) = (render(&up, "framing", "up-framing.png"), render(&down, "framing", "down-framing.png"));
    assert!(a.pixels().zip(b.pixels()).any(|(p, q)| p != q), "framing ignores the frame: the two differ");
}

#[test]
fn info_prints_the_orientation_code() {
    let [up, down] = files("info");
    for (f, code) in [(&up, "RAS"), (&down, "RAI")] {
        let o = voxsplat(&["info", f.to_str().unwrap()]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success() && text.contains(&format!("orientation: {code}")), "{text}");
    }
}

#[test]
fn an_anatomical_view_of_data_without_a_frame_is_refused() {
    let o = voxsplat(&["render", "--scene", "cube40", "--view", "anterior", "--out", tmp("x.png").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("anatomical frame") && !err.contains("panicked"), "{err}");
}

/// A column of voxels along k in a CT whose gantry is tilted 30 degrees: each slice lies 0.577
/// units further anterior than the one below, so the column leans toward anterior in the world.
#[test]
fn a_tilted_gantry_leans_as_the_file_says() {
    let [nx, ny, nz] = DIMS;
    let mut v = Vec::new();
    for _ in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                v.push(((5..=6).contains(&i) && (4..=5).contains(&j)) as u8 * 200);
            }
        }
    }
    let tilt = 30f64.to_radians().tan();
    let path = tmp("tilted.nii");
    std::fs::write(
        &path,
        nifti(DIMS, &v, Some(affine([DVec3::X, DVec3::Y, DVec3::new(0.0, tilt, 1.0)], DVec3::ZERO)), None),
    )
    .unwrap();
    let o = voxsplat(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("sheared: axes i-j at 90.0, i-k at 90.0, j-k at 60.0 degrees"),
        "{text}"
    );
    // From the patient's left anterior is to the image's left: the column's upper rows lie left
    // of its lower ones, by the tilt (pixels per pixel: the view is square on the column).
    for extra in [&[][..], &["--dense"][..]] {
        let img = render_with(&path, "left", &format!("tilted{}.png", extra.len()), extra);
        let centre = |rows: std::ops::Range<u32>| {
            let (mut s, mut w) = (0.0, 0.0);
            for y in rows {
                for x in 0..img.width() {
                    let a = img.get_pixel(x, y)[3] as f64;
                    (s, w) = (s + x as f64 * a, w + a);
                }
            }
            assert!(w > 0.0, "{extra:?}: the column is drawn");
            s / w
        };
        let (rows, top, bottom) = (8..24u32, 24..40u32, 40..56u32);
        let lean = (centre(bottom.clone()) - centre(rows.clone())) / 32.0;
        eprintln!(
            "{extra:?}: lean {lean:.3} px per px ({:.1}, {:.1}, {:.1})",
            centre(rows),
            centre(top),
            centre(bottom)
        );
        assert!((lean - tilt).abs() < 0.15, "{extra:?}: the column leans {lean} px per px, the file says {tilt}");
    }
}
