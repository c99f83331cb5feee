//! Issue 9: the peers' scene reproduced; voxsplat's reference integration agrees with VTK.
use voxsplat::scene::peer;
use voxsplat::{classify, truth};

/// The generated volume and transfer function give exactly the peers' 208,483 visible voxels
/// (../shared/peers/README.md).
#[test]
fn the_peer_scene_has_the_peers_voxel_count() {
    let set = classify::classify(&peer::volume(128).unwrap(), &peer::transfer_function(), None).unwrap();
    assert_eq!(set.len(), 208_483);
    assert!(peer::volume(1).is_err() && peer::volume(100_000).is_err());
}

/// One truth: voxsplat's ray integration of the interpolated scalar matches VTK's GPU ray caster at
/// the same 0.1-voxel sample distance (a stored render: tests/data, made by
/// `../shared/peers/vtk/vtk_volume.py --mapper gpu --n 64 --size 128 --sample 0.1`) to >= 40 dB over
/// the object's pixels, so the volume, the transfer function's conventions and the camera line up.
#[test]
fn scalar_ray_integration_agrees_with_vtk() {
    let vtk = image::open(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/vtk-gpu-peer64-128px-s0.1.png"))
        .unwrap()
        .to_rgb8();
    let ours = truth::ray_integrate_scalars(
        &peer::volume(64).unwrap(),
        &peer::transfer_function(),
        &peer::camera(64, 128),
        0.1,
    )
    .unwrap();
    let (mut se, mut count) = (0.0f64, 0usize);
    for (i, p) in ours.pixels.iter().enumerate() {
        let v = vtk.as_raw()[3 * i..3 * i + 3].iter().map(|&c| c as f64).collect::<Vec<_>>();
        if p[3] <= 1.0 / 255.0 && v.iter().all(|&c| c == 0.0) {
            continue;
        }
        for c in 0..3 {
            let o = (p[c].clamp(0.0, 1.0) as f64 * 255.0).round();
            se += (o - v[c]).powi(2);
        }
        count += 1;
    }
    let psnr = 10.0 * (255.0f64.powi(2) / (se / (3 * count) as f64)).log10();
    eprintln!("PSNR against VTK GPU: {psnr:.2} dB over {count} pixels");
    assert!(count > 2000, "the object covers the frame");
    assert!(psnr >= 40.0, "{psnr} dB");
}
