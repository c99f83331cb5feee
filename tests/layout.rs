//! The core's layout stays as docs/DEVELOPING.md's "Layout" section draws it: no module imports another that
//! (through others) imports it back, the maths reaches into no executor, and no source file grows
//! past ~700 lines.
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level module -> the top-level modules its code (not its comments) names as `crate::x`.
fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap().to_str().unwrap().trim_end_matches(".rs").to_string();
        if rel == "lib" {
            continue;
        }
        let top = rel.split('/').next().unwrap().to_string();
        let uses = graph.entry(top.clone()).or_default();
        for line in std::fs::read_to_string(f).unwrap().lines() {
            let code = line.split("//").next().unwrap();
            for (i, _) in code.match_indices("crate::") {
                let name: String = code[i + 7..].chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
                if !name.is_empty() && name != top {
                    uses.insert(name);
                }
            }
        }
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    graph.values_mut().for_each(|u| u.retain(|m| modules.contains(m)));
    graph
}

fn reaches(graph: &BTreeMap<String, BTreeSet<String>>, from: &str, to: &str) -> bool {
    let mut seen = BTreeSet::new();
    let mut stack: Vec<&str> = graph[from].iter().map(String::as_str).collect();
    while let Some(m) = stack.pop() {
        if m == to {
            return true;
        }
        if seen.insert(m) {
            stack.extend(graph.get(m).into_iter().flatten().map(String::as_str));
        }
    }
    false
}

#[test]
fn no_module_import_loops() {
    let graph = module_graph();
    assert!(graph.len() > 25, "modules found: {graph:?}");
    let loops: Vec<_> = graph.keys().filter(|m| reaches(&graph, m, m)).collect();
    assert!(loops.is_empty(), "modules on an import loop: {loops:?}\n{graph:#?}");
}

#[test]
fn the_maths_reaches_into_no_executor() {
    let graph = module_graph();
    for maths in ["camera", "kernel", "order", "volume"] {
        for executor in ["cpu", "cpu_engine", "gpu", "vk", "stages", "recording", "dispatch"] {
            assert!(!reaches(&graph, maths, executor), "{maths} reaches {executor}");
        }
    }
}

#[test]
fn no_core_source_file_passes_700_lines() {
    let mut stack = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("src")];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let lines = std::fs::read_to_string(&p).unwrap().lines().count();
                assert!(lines <= 700, "{} has {lines} lines", p.display());
            }
        }
    }
}
