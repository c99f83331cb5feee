//! Long runs do not leak (`voxsplat-lab soak`).
use crate::common;

/// GPU allocations must not drift (host memory: the next test, in a child process).
#[test]
fn a_100_frame_soak_keeps_gpu_allocations_flat() {
    let mut r = common::gpu();
    let rep = voxsplat_lab::soak::soak(&mut r, 100, 64, |_| {}).unwrap();
    eprintln!("gpu per cycle {:?}", rep.gpu);
    eprintln!("rss per cycle (MiB) {:?}", rep.rss.iter().map(|b| b / (1 << 20)).collect::<Vec<_>>());
    // After the first cycle (warm-up) every cycle starts with the same live allocations. lavapipe's
    // memory requirement for a re-created image can differ by an alignment step (32 bytes seen), so
    // the byte total may move by that much but must not grow with the cycles.
    assert!(rep.gpu.len() >= 8);
    for g in &rep.gpu[2..] {
        assert_eq!(g.0, rep.gpu[1].0, "the number of live GPU allocations drifts: {:?}", rep.gpu);
        assert!(g.1.abs_diff(rep.gpu[1].1) <= 4096, "GPU bytes drift: {:?}", rep.gpu);
    }
    assert_eq!(rep.validation_messages, 0);
    common::assert_clean(&r);
}

/// Host memory must not grow after warm-up. In a child process so that the test harness's own
/// allocations do not count and the allocator can be configured (see `SoakReport::rss_growth`).
/// Before the frame constants moved from a uniform to a storage buffer, lavapipe grew by
/// 0.2-0.7 MB per frame here, about 5 MiB per cycle.
#[test]
fn a_120_frame_soak_keeps_host_memory_flat() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_voxsplat-lab"))
        .args(["soak", "--frames", "120", "--size", "64", "--validation"])
        .env("MALLOC_MMAP_THRESHOLD_", "131072")
        .env("MALLOC_ARENA_MAX", "1")
        .output()
        .expect("run voxsplat-lab soak");
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success());
    let figure = |prefix: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(prefix))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .expect(prefix)
    };
    // A leak moves every cycle: the old uniform-buffer leak measured ~5 MiB per 12-frame cycle here.
    // One-off steps (driver pools, allocator arenas) move one cycle and leave the median alone.
    let step = figure("rss median step per cycle after warm-up: ");
    eprintln!("peak growth {} MiB", figure("rss peak growth after warm-up: "));
    assert!(step < 1.0, "host RSS grows {step} MiB per cycle after warm-up");
    assert!(text.contains("validation messages: 0"));
}
