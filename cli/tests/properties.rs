//! Property tests through the whole command-line render path (issue 25): random scenes, cameras,
//! sizes and modes give either a frame of the asked size or a typed error (exit 2), never a panic
//! and never a validation message.
use crate::cmd;
use proptest::prelude::*;

fn pick(options: &'static [&'static str]) -> impl Strategy<Value = &'static str> {
    prop::sample::select(options)
}

proptest! {
    // 64 cases in CI (about 15 s); PROPTEST_CASES=N for a longer hunt.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]
    #[test]
    fn a_render_request_gives_its_frame_or_a_typed_error(
        (w, h) in (1u32..97, 1u32..97),
        scene in pick(&["cube40", "cube40-attenuated", "plane", "empty", "solid40"]),
        composite in pick(&["splat", "sheet", "slab"]),
        raster in pick(&["auto", "graphics", "compute", "points"]),
        kernel in pick(&["gaussian", "cubic", "narrow", "crawfis-max"]),
        aa in pick(&["none", "swan", "ewa"]),
        order in pick(&["pbtf", "btf", "wbtf", "sorted"]),
        eye in prop::option::of((-150f32..150.0, -150f32..150.0, -150f32..150.0)),
        view in prop::option::of(prop_oneof![(5f32..150.0).prop_map(|f| ("--fov", f)), (0.01f32..300.0).prop_map(|o| ("--ortho", o))]),
        exr in any::<bool>(),
        cpu in any::<bool>(),
    ) {
        let out = std::env::temp_dir().join(format!("voxsplat-prop-{}.{}", std::process::id(), if exr { "exr" } else { "png" }));
        let size = format!("{w}x{h}");
        let mut args: Vec<String> = ["render", "--scene", scene, "--size", &size, "--accumulate", composite, "--raster", raster,
            "--kernel", kernel, "--aa", aa, "--order", order, "--out", out.to_str().unwrap()]
            .iter().map(|s| s.to_string()).collect();
        if let Some((x, y, z)) = eye {
            args.extend(["--eye".to_string(), format!("{x},{y},{z}")]);
        }
        if let Some((flag, v)) = view {
            args.extend([flag.to_string(), v.to_string()]);
        }
        args.push(if cpu { "--cpu" } else { "--validation" }.to_string());
        let _ = std::fs::remove_file(&out);
        let run = cmd::voxsplat(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let err = String::from_utf8_lossy(&run.stderr);
        prop_assert!(!err.contains("panicked") && !err.contains("validation"), "{args:?}: {err}");
        match run.status.code() {
            Some(0) => {
                let img = voxsplat::output::read_image(&out).unwrap();
                prop_assert_eq!((img.width, img.height), (w, h), "{:?}", args);
                prop_assert!(img.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())), "{:?}", args);
            }
            Some(2) => prop_assert!(err.lines().any(|l| l.starts_with("error: ")), "{args:?}: {err}"),
            other => prop_assert!(false, "{args:?}: exit {other:?}: {err}"),
        }
    }
}
