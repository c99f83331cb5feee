//! The README's commands run as written: every `cargo run --release -- ...` line of its `sh` blocks
//! runs the built binary with those arguments in a fresh directory (`../shared/data` read from
//! where the data lives), and each must succeed and write what it names. The set-up and test
//! commands (`./scripts/setup.sh`, `cargo test`) are what CI itself runs, so they are listed, not
//! run. The README's Rust example is a doc test of the core crate (`src/lib.rs`).
use crate::cmd;
use std::path::Path;
use std::process::Command;

const README: &str = include_str!("../../README.md");

/// The lines of the README's ```sh blocks; every block names its language.
fn shell_lines() -> Vec<&'static str> {
    let (mut lines, mut block) = (Vec::new(), None);
    for line in README.lines().map(str::trim_start) {
        if let Some(fence) = line.strip_prefix("```") {
            block = match block {
                None => {
                    assert!(!fence.trim().is_empty(), "a README code block without a language");
                    Some(fence.trim())
                }
                Some(_) => None,
            };
        } else if block == Some("sh") && !line.is_empty() {
            lines.push(line);
        }
    }
    lines
}

#[test]
fn every_readme_command_runs_as_written() {
    let data = voxsplat::loaders::data_dir();
    if !data.join("bonsai/bonsai.nii.gz").exists() {
        panic!("the README's commands read ../shared/data (or $VOXSPLAT_DATA): not found at {}", data.display());
    }
    let dir = cmd::tmp_in("readme", "run");
    std::fs::create_dir_all(&dir).unwrap();
    let mut ran = 0;
    for line in shell_lines() {
        let commands: Vec<&str> = line.split("&&").map(str::trim).collect();
        for c in commands {
            if c.starts_with("./scripts/setup.sh") || c.starts_with("cargo test") {
                continue;
            }
            let args = c
                .strip_prefix("cargo run --release -- ")
                .unwrap_or_else(|| panic!("a README command this test cannot run: {c}"));
            assert!(!args.contains(['"', '\'', '$', '|', '>']), "a README command with shell syntax: {c}");
            let args: Vec<String> = args
                .split_whitespace()
                .map(|a| match a.strip_prefix("../shared/data/") {
                    Some(rest) => data.join(rest).display().to_string(),
                    None => a.to_string(),
                })
                .collect();
            let mut runs = vec![args.clone()];
            if args[0] == "render" {
                // And once more with the validation layer on: any message fails the command.
                let mut v = args.clone();
                v.push("--validation".into());
                runs.push(v);
            }
            for a in runs {
                let out = Command::new(env!("CARGO_BIN_EXE_voxsplat")).args(&a).current_dir(&dir).output().unwrap();
                assert!(out.status.success(), "README command failed: {c}\n{}", String::from_utf8_lossy(&out.stderr));
                for (flag, what) in a.iter().zip(a.iter().skip(1)) {
                    if flag == "--out" || flag == "--out-dir" {
                        assert!(Path::new(&dir).join(what).exists(), "{c} wrote no {what}");
                    }
                }
                if a[0] == "compare" {
                    assert!(String::from_utf8_lossy(&out.stdout).contains("psnr:"), "{c} printed no PSNR");
                }
                if a.iter().any(|f| f == "--plan") {
                    let plan = String::from_utf8_lossy(&out.stdout);
                    assert!(plan.contains("draw ") && plan.contains("budget "), "{c} printed no plan: {plan}");
                }
                if a[0] == "info" {
                    assert!(String::from_utf8_lossy(&out.stdout).contains("volume:"), "{c} printed no volume line");
                }
            }
            ran += 1;
        }
    }
    assert!(ran >= 6, "the README's command tour ran only {ran} commands");
}

#[test]
fn the_readme_stays_short_and_names_no_issue_numbers() {
    let lines = README.lines().count();
    assert!((60..=250).contains(&lines), "README has {lines} lines (about 150-250 asked)");
    let first_commands = README.lines().position(|l| l.contains("./scripts/setup.sh &&")).unwrap();
    assert!(first_commands < 40, "the two commands start at line {}", first_commands + 1);
    for (i, l) in README.lines().enumerate() {
        let lower = l.to_lowercase();
        let named = lower.match_indices("issue").any(|(at, _)| {
            let after = lower[at + 5..].trim_start_matches([' ', '#']);
            after.starts_with(|c: char| c.is_ascii_digit())
        });
        assert!(!named, "README line {} names an issue number: {l}", i + 1);
    }
}

/// The guide's TOML examples are what the readers read: a transfer function (the first block), a
/// label table and an animation.
#[test]
fn the_guides_toml_examples_parse() {
    let guide = include_str!("../../docs/guide/cli.md");
    let mut blocks = Vec::new();
    let mut block: Option<String> = None;
    for line in guide.lines() {
        match (&mut block, line.trim_start().strip_prefix("```")) {
            (None, Some("toml")) => block = Some(String::new()),
            (Some(b), Some(_)) => {
                blocks.push(std::mem::take(b));
                block = None;
            }
            (Some(b), None) => {
                b.push_str(line);
                b.push('\n');
            }
            _ => {}
        }
    }
    assert_eq!(blocks.len(), 3, "the guide's TOML blocks: {blocks:?}");
    let tf = voxsplat::classify::TransferFunction::from_toml(&blocks[0]).unwrap();
    assert_eq!((tf.points.len(), tf.range), (3, Some((0.0, 4095.0))));
    let labels = voxsplat::labels::LabelTable::from_toml(&blocks[1]).unwrap();
    assert_eq!(labels.labels.len(), 2);
    assert!(labels.get(1).unwrap().visible && !labels.get(2).unwrap().visible);
    let anim = voxsplat::animate::Animation::from_toml(&blocks[2]).unwrap();
    assert_eq!(anim.frames, 24);
}
