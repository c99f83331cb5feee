//! The command-line tool's fuzz corpus (bench reports, viewer sessions) replayed through the fuzz
//! targets' own bodies (fuzz/cli_bodies.rs), as tests/fuzz_corpus.rs replays the loaders': the
//! seeds (fuzz/seeds/TARGET) and the kept corpus (fuzz/corpus/TARGET) on every CI run.
use std::path::Path;
include!("../../fuzz/cli_bodies.rs");

#[test]
fn every_seed_and_corpus_input_reads_without_a_panic() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
    for (target, body) in [("report", report as fn(&[u8])), ("session", session)] {
        let list = |dir: &Path| -> Vec<_> {
            let mut f: Vec<_> = std::fs::read_dir(dir).map_or(vec![], |d| d.map(|e| e.unwrap().path()).collect());
            f.sort();
            f
        };
        let seeds = list(&fuzz.join("seeds").join(target));
        assert!(!seeds.is_empty(), "fuzz/seeds/{target} is empty");
        for input in seeds.into_iter().chain(list(&fuzz.join("corpus").join(target))) {
            body(&std::fs::read(&input).unwrap());
        }
    }
}

/// The valid seeds read: the fuzzers start from files that reach past the parsers.
#[test]
fn the_valid_seeds_read() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds");
    let r = voxsplat_cli::suite::Report::read_json(&seeds.join("report/two-cases.json")).unwrap();
    assert!(voxsplat_cli::suite::compare(&r, &r).unwrap().contains("1.000x"));
    for name in ["composite.toml", "ortho-mip.toml"] {
        let s = voxsplat_cli::session::Session::load(&seeds.join("session").join(name)).unwrap();
        s.camera(64, 48).unwrap();
    }
}
