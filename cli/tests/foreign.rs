//! Issue 76: files as other tools write them, which read as something other than they hold (a
//! spacing of 1, a constant volume) and now read right or are refused naming the file, the field
//! and the value. Each file is written by the tool its users have: pynrrd, pydicom, tifffile.
use crate::cmd;
use cmd::python;
use std::path::PathBuf;
use voxsplat::loaders::{load_volume, VolumeHints};

fn tmp(name: &str) -> PathBuf {
    cmd::tmp_in("foreign", name)
}

/// A 4 x 5 x 6 NRRD of `u8` with the header lines `fields` (written here: pynrrd writes only
/// well-formed spacings).
fn nrrd(name: &str, fields: &str) -> PathBuf {
    let p = tmp(name);
    let header = format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 5 6\nencoding: raw\n{fields}\n\n");
    std::fs::write(&p, [header.as_bytes(), &[7u8; 120][..]].concat()).unwrap();
    p
}

#[test]
fn nrrd_spacing_is_read_from_space_directions_and_malformed_spacings_are_refused() {
    // pynrrd's `space dimension` with directions (no named space): spacing [1, 1, 1] before.
    let sd = tmp("space-dimension.nrrd");
    python(
        "import nrrd, numpy as np\nnrrd.write('{}', np.zeros((4, 5, 6), np.uint8) + 7, \
         {'space dimension': 3, 'space directions': np.diag([2.0, 3.0, 4.0])})",
        &[&sd],
    );
    let text = std::fs::read_to_string(&sd).unwrap_or_default();
    let v = load_volume(&sd, &VolumeHints::default()).unwrap();
    assert_eq!(
        (v.dims, v.spacing),
        ([4, 5, 6], [2.0, 3.0, 4.0]),
        "{}",
        text.lines().take(9).collect::<Vec<_>>().join("; ")
    );
    assert_eq!(
        load_volume(&nrrd("plain.nrrd", "spacings: 2 3 4"), &VolumeHints::default()).unwrap().spacing,
        [2.0, 3.0, 4.0]
    );
    for (name, field, says) in [
        ("units.nrrd", "spacings: 2mm 3mm 4mm", "'2mm' is not a number"),
        ("commas.nrrd", "spacings: 2,3,4", "holds 1 values for 3 axes"),
        ("word.nrrd", "spacings: 2 3 abc", "'abc' is not a number"),
        ("short.nrrd", "spacings: 2 3", "holds 2 values for 3 axes"),
    ] {
        let p = nrrd(name, field);
        let e = load_volume(&p, &VolumeHints::default()).unwrap_err().to_string();
        assert!(e.contains(says) && e.contains(p.to_str().unwrap()), "{name}: {e}");
    }
}

#[test]
fn tiff_stacks_keep_their_units_and_refuse_packed_bits_and_mixed_sample_types() {
    // tifffile's OME-TIFF with x and y in mm and z in nm: z was drawn 10^6 times too long.
    let ome = tmp("units.ome.tif");
    python(
        "import tifffile, numpy as np\ntifffile.imwrite('{}', np.full((3, 4, 5), 9, np.uint8), metadata={'axes': 'ZYX', \
         'PhysicalSizeX': 0.5, 'PhysicalSizeXUnit': 'mm', 'PhysicalSizeY': 0.25, 'PhysicalSizeYUnit': 'mm', \
         'PhysicalSizeZ': 2000, 'PhysicalSizeZUnit': 'nm'})",
        &[&ome],
    );
    let v = load_volume(&ome, &VolumeHints::default()).unwrap();
    assert_eq!(v.dims, [5, 4, 3]);
    let want = [0.5, 0.25, 0.002];
    assert!(v.spacing.iter().zip(want).all(|(s, w)| (s - w).abs() < 1e-6 * w), "{:?}", v.spacing);
    // No unit named: OME's µm for each, as before.
    let plain = tmp("plain.ome.tif");
    python(
        "import tifffile, numpy as np\ntifffile.imwrite('{}', np.full((3, 4, 5), 9, np.uint8), metadata={'axes': 'ZYX', \
         'PhysicalSizeX': 0.5, 'PhysicalSizeY': 0.25, 'PhysicalSizeZ': 2.0})",
        &[&plain],
    );
    assert_eq!(load_volume(&plain, &VolumeHints::default()).unwrap().spacing, [0.5, 0.25, 2.0]);
    // A 1-bit mask (tifffile writes bool as bilevel): read a byte a sample past the strip before.
    let mask = tmp("mask.tif");
    python("import tifffile, numpy as np\ntifffile.imwrite('{}', np.indices((3, 32, 32)).sum(0) % 2 == 0)", &[&mask]);
    let e = load_volume(&mask, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("1-bit samples") && e.contains(mask.to_str().unwrap()), "{e}");
    // A folder of 8- and 16-bit slices: the 8-bit ones sat at 0.4 % of the range before.
    let dir = tmp("mixed");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    python(
        "import tifffile, numpy as np\nfor i in range(3):\n    \
         tifffile.imwrite('{}/s%d.tif' % i, np.full((4, 5), 200, np.uint8 if i == 1 else np.uint16))",
        &[&dir],
    );
    let e = load_volume(&dir, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("s1.tif") && e.contains("8-bit samples") && e.contains("16-bit"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn geotiff_no_data_cells_are_holes_not_heights() {
    // A hill of 0..90 m in a 40 x 30 grid whose border is GDAL's no-data -9999 (tifffile writes the
    // tag as GDAL does): the border was drawn at -9999, the hill a flat slab 10^4 m above it.
    let dem = tmp("hill.tif");
    python(
        "import tifffile, numpy as np\ny, x = np.mgrid[:30, :40]\nh = (90 * np.exp(-((x - 20) ** 2 + (y - 15) ** 2) / 60))\
         .astype(np.float32)\nh[:3, :] = -9999\nh[:, :2] = -9999\ntifffile.imwrite('{}', h, \
         extratags=[(42113, 's', 0, '-9999', True)])",
        &[&dem],
    );
    let h = voxsplat::loaders::load_heights(&dem).unwrap();
    let holes = h.heights.iter().filter(|v| v.is_nan()).count();
    assert_eq!(holes, 3 * 40 + 27 * 2, "the no-data cells");
    let fine = h.heights.iter().filter(|v| v.is_finite()).fold(f32::MAX, |a, &b| a.min(b));
    assert!(fine >= 0.0, "the lowest height is the hill's: {fine}");
    let opts = voxsplat::terrain::TerrainOptions { cell: 1.0, ..Default::default() };
    let set = voxsplat::terrain::terrain_splats(&h, &opts).unwrap();
    // The hill's relief, not 10^4 levels; no column where there is no height.
    assert!(set.grid().dims[2] <= 92, "{:?}", set.grid().dims);
    let rows = set.grid().dims[1];
    for s in set.splats() {
        let [i, j] = [s.ijk[0], rows - 1 - s.ijk[1]];
        assert!(j >= 3 && i >= 2, "a column at the no-data cell ({i}, {j})");
    }
    // Drawn: the hill covers pixels.
    let out = tmp("hill.png");
    let run = cmd::voxsplat(&[
        "render",
        "--terrain",
        dem.to_str().unwrap(),
        "--size",
        "64x48",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
}

#[test]
fn refusals_blame_the_field_at_fault() {
    // nibabel's NIfTI with dim[1] set to 0: the parser blamed "dim[0] = 3".
    let nii = tmp("dim1.nii");
    python(
        "import nibabel, numpy as np, struct\nnibabel.save(nibabel.Nifti1Image(np.zeros((4, 4, 4), np.uint8), np.eye(4)), \
         '{}')\nb = bytearray(open('{}', 'rb').read())\nstruct.pack_into('<h', b, 42, 0)\nopen('{}', 'wb').write(b)",
        &[&nii, &nii, &nii],
    );
    let e = load_volume(&nii, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("dim[1] = 0"), "{e}");
    // zarr-python's OME-Zarr whose .zattrs is cut short: it was taken for a folder of slices.
    let zarr = tmp("cut.zarr");
    let _ = std::fs::remove_dir_all(&zarr);
    python(
        "import zarr\nroot = zarr.open_group('{}', mode='w', zarr_format=2)\nroot.create_array('0', shape=(4, 4, 4), \
         dtype='u1')\nroot.attrs['multiscales'] = [{'version': '0.4', 'axes': [{'name': a, 'type': 'space'} for a in \
         'zyx'], 'datasets': [{'path': '0', 'coordinateTransformations': [{'type': 'scale', 'scale': [1, 1, 1]}]}]}]",
        &[&zarr],
    );
    let attrs = zarr.join(".zattrs");
    let text = std::fs::read_to_string(&attrs).unwrap();
    std::fs::write(&attrs, &text[..text.len() / 2]).unwrap();
    let e = cmd::refused(&["info", zarr.to_str().unwrap()]);
    assert!(e.contains(".zattrs") && e.contains("JSON"), "{e}");
    // nibabel's NIfTI with a pixdim, an sform step or an sform origin of 1e30: each drew nothing
    // or blamed the camera ("eye, target and up must be finite").
    let d = "import nibabel as nib, numpy as np\nd = np.zeros((8, 8, 8), np.uint8); d[2:6, 2:6, 2:6] = 200\n";
    for (name, make, says) in [
        (
            "pixdim.nii",
            "i = nib.Nifti1Image(d, None); i.header['pixdim'][1:4] = [1e30, 1, 1]; i.set_sform(None, 0)\n\
             i.set_qform(None, 0)\n",
            "spacing [1e30",
        ),
        ("sform.nii", "a = np.diag([1e30, 1, 1, 1]); i = nib.Nifti1Image(d, a); i.set_qform(None, 0)\n", "voxel step"),
        ("origin.nii", "a = np.eye(4); a[0, 3] = 1e30; i = nib.Nifti1Image(d, a)\n", "origin"),
    ] {
        let nii = tmp(name);
        python(&format!("{d}{make}nib.save(i, '{{}}')"), &[&nii]);
        let e = cmd::refused(&["render", "--volume", nii.to_str().unwrap(), "--size", "16x16", "--out", "x.png"]);
        assert!(e.contains(says) && !e.contains("invalid camera"), "{name}: {e}");
    }
}

/// zarr-python's OME-Zarr images (issue 76): a z axis in nanometres beside x and y in micrometres
/// is scaled into micrometres (it drew z a thousand times too long), and spatial axes named x, y,
/// z in array order x, y, z are refused (they were scaled as z, y, x).
#[test]
fn ome_zarr_axes_keep_their_units_and_their_names() {
    let write = |name: &str, axes: &str, scale: &str| {
        let dir = tmp(name);
        let _ = std::fs::remove_dir_all(&dir);
        let script = format!(
            "import zarr, numpy as np\nroot = zarr.open_group('{{}}', mode='w', zarr_format=2)\n\
             a = root.create_array('0', shape=(4, 5, 6), dtype='u1')\na[:] = np.arange(120).reshape(4, 5, 6)\n\
             root.attrs['multiscales'] = [{{'version': '0.4', 'axes': {axes}, 'datasets': [{{'path': '0', \
             'coordinateTransformations': [{{'type': 'scale', 'scale': {scale}}}]}}]}}]"
        );
        python(&script, &[&dir]);
        dir
    };
    let units = write(
        "units.zarr",
        "[{'name': 'z', 'type': 'space', 'unit': 'nanometer'}, {'name': 'y', 'type': 'space', 'unit': 'micrometer'}, \
         {'name': 'x', 'type': 'space', 'unit': 'micrometer'}]",
        "[2000.0, 0.5, 0.25]",
    );
    let v = load_volume(&units, &VolumeHints::default()).unwrap();
    assert_eq!(v.dims, [6, 5, 4]);
    let want = [0.25, 0.5, 2.0];
    assert!(v.spacing.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6), "{:?} against {want:?}", v.spacing);
    let swapped = write(
        "xyz.zarr",
        "[{'name': 'x', 'type': 'space'}, {'name': 'y', 'type': 'space'}, {'name': 'z', 'type': 'space'}]",
        "[1.0, 1.0, 3.0]",
    );
    let e = cmd::refused(&["info", swapped.to_str().unwrap()]);
    assert!(e.contains("[\"x\", \"y\", \"z\"]") && e.contains("z, y, x"), "{e}");
    let seconds = write(
        "seconds.zarr",
        "[{'name': 'z', 'type': 'space', 'unit': 'second'}, {'name': 'y', 'type': 'space'}, {'name': 'x', 'type': 'space'}]",
        "[1.0, 1.0, 1.0]",
    );
    let e = cmd::refused(&["info", seconds.to_str().unwrap()]);
    assert!(e.contains("axis z has unit \"second\""), "{e}");
}

/// pynrrd's NRRD of 2 channels and nibabel's NIfTI of 3 (issue 76): `info` describes each channel
/// and `render --channel-tf` draws them (the NRRD was refused by both, "holds 2 channels").
#[test]
fn files_of_channels_are_described_and_drawn() {
    let (nrrd, nii) = (tmp("two.nrrd"), tmp("three.nii"));
    python(
        "import nrrd, nibabel, numpy as np\nd = np.zeros((2, 16, 16, 16), np.uint8)\nd[0, 4:12, 4:12, 4:12] = 200\n\
         d[1, 2:8, 2:8, 2:8] = 150\nnrrd.write('{}', d, {'kinds': ['vector', 'domain', 'domain', 'domain']}, \
         index_order='F')\nv = np.zeros((16, 16, 16, 1, 3), np.uint8)\nv[4:12, 4:12, 4:12, 0, :] = [200, 150, 100]\n\
         nibabel.save(nibabel.Nifti1Image(v, np.eye(4)), '{}')",
        &[&nrrd, &nii],
    );
    for (file, n, tfs) in
        [(&nrrd, 2, vec!["--channel-tf", "bonsai"]), (&nii, 3, vec!["--channel-tf", "bonsai", "--channel-tf", "ct"])]
    {
        let out = cmd::voxsplat(&["info", file.to_str().unwrap()]);
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && said.contains(&format!("{n} channels")),
            "{said}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(said.contains(&format!("channel {}: [16, 16, 16] voxels", n - 1)), "{said}");
        let png = tmp("channels.png");
        let args = [
            &["render", "--volume", file.to_str().unwrap()][..],
            &tfs,
            &["--size", "32x32", "--out", png.to_str().unwrap()],
        ]
        .concat();
        let out = cmd::voxsplat(&args);
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        // `slice` and `make-volume --from` take one channel (refused outright before).
        let f = file.to_str().unwrap();
        let e = cmd::refused(&["slice", f, "--out", png.to_str().unwrap()]);
        assert!(e.contains(&format!("holds {n} channels: pick one with --channel N")), "{e}");
        let last = (n - 1).to_string();
        let out = cmd::voxsplat(&["slice", f, "--channel", &last, "--index", "4", "--out", png.to_str().unwrap()]);
        let said = String::from_utf8_lossy(&out.stdout);
        // The last channel's value inside its cube (through plane 4): 150 (NRRD) or 100 (NIfTI).
        let top = if n == 2 { "values 0 .. 150" } else { "values 0 .. 100" };
        assert!(out.status.success() && said.contains(top), "{said}{}", String::from_utf8_lossy(&out.stderr));
        assert!(cmd::refused(&["slice", f, "--channel", &n.to_string(), "--out", "x.png"]).contains("(0 to"));
        let up = tmp("channel.nrrd");
        let out = cmd::voxsplat(&["make-volume", "--from", f, "--channel", "0", "--out", up.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(load_volume(&up, &VolumeHints::default()).unwrap().dims, [32, 32, 32]);
    }
}

#[test]
fn wide_values_stay_in_range_and_values_f32_would_flatten_are_refused() {
    // nibabel's uint32 and int32 at their types' limits, a float64 ball on an offset of 1e10 and an
    // int32 ball on 2e9 (both drew flat: f32 steps of 1024 and 128 there), numpy's float64 the same.
    let [u32n, i32n, f64n, i32b, npy] = ["u32.nii", "i32.nii", "f64.nii", "i32-ball.nii", "f64.npy"].map(tmp);
    python(
        "import nibabel, numpy as np\n\
         def save(a, p): nibabel.save(nibabel.Nifti1Image(a, np.eye(4)), p)\n\
         z, y, x = np.mgrid[:16, :16, :16]\nball = ((x - 8) ** 2 + (y - 8) ** 2 + (z - 8) ** 2 < 25)\n\
         u = np.zeros((16, 16, 16), np.uint32)\nu[ball] = 4294967295\nsave(u, '{}')\n\
         i = np.full((16, 16, 16), -2147483648, np.int32)\ni[ball] = 2147483647\nsave(i, '{}')\n\
         save(1e10 + ball.astype(np.float64), '{}')\nsave((2000000000 + 100 * ball).astype(np.int32), '{}')\n\
         np.save('{}', 1e10 + ball.astype(np.float64))",
        &[&u32n, &i32n, &f64n, &i32b, &npy],
    );
    for (file, lo, hi) in [(&u32n, 0.0, u32::MAX as f64), (&i32n, i32::MIN as f64, i32::MAX as f64)] {
        let out = cmd::voxsplat(&["info", file.to_str().unwrap()]);
        let said = String::from_utf8_lossy(&out.stdout);
        let values = said.lines().find_map(|l| l.split_once("values ")).map(|(_, v)| v.to_string());
        let values = values.unwrap_or_else(|| panic!("{said}{}", String::from_utf8_lossy(&out.stderr)));
        let (a, b) = values.split_once(" .. ").unwrap();
        let (a, b) = (a.parse::<f64>().unwrap(), b.parse::<f64>().unwrap());
        // Within the type's range and within one f32 step (512 near 2^32) of its ends.
        assert!(a >= lo && b <= hi && a - lo < 512.0 && hi - b < 512.0, "{}: {values}", file.display());
        let png = tmp("wide.png");
        let out = cmd::voxsplat(&[
            "render",
            "--volume",
            file.to_str().unwrap(),
            "--size",
            "32x32",
            "--out",
            png.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    for file in [&f64n, &i32b, &npy] {
        for args in [
            vec!["info", file.to_str().unwrap()],
            vec!["render", "--volume", file.to_str().unwrap(), "--size", "16x16", "--out", "x.png"],
        ] {
            let e = cmd::refused(&args);
            assert!(e.contains(file.to_str().unwrap()) && e.contains("Subtract their offset"), "{args:?}: {e}");
        }
    }
}
