//! The layout stays as docs/DEVELOPING.md's "Layout" section draws it: no module, and no file of the
//! core or the CLI, imports another that (through others) imports it back; the maths reaches into
//! no executor, nor (but for `SplatSet`'s records) the GPU layout; the Vulkan engine, the
//! recording and the plan import no CPU mirror; the formats
//! (loaders, scenes, terrain, classification, output, orientation) import no study; no module
//! imports a layer above the crate it will move to (docs/DEVELOPING.md, "The crates to come"); and
//! no source file of the core, the CLI or the lab grows past 700 lines.
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level module -> the top-level modules its code (not its comments) names as `crate::x`.
fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = rust_files(&src);
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
fn no_source_file_of_the_core_the_cli_or_the_lab_passes_700_lines() {
    for dir in ["src", "cli/src", "lab/src"] {
        for p in rust_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join(dir)) {
            let lines = std::fs::read_to_string(&p).unwrap().lines().count();
            assert!(lines <= 700, "{} has {lines} lines", p.display());
        }
    }
}

/// Every `.rs` file under `root`.
fn rust_files(root: &Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![root.to_path_buf()];
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
    files.sort();
    files
}

/// The paths a `use` tree or path expression at the start of `s` names: `a::{b, c::d}` ->
/// [a, b], [a, c, d]. Segments run while they are identifiers; a group is read to its brace.
fn path_tree(s: &str) -> Vec<Vec<String>> {
    fn tree(s: &[char], i: &mut usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
        let mut path = prefix;
        loop {
            while *i < s.len() && s[*i] == ' ' {
                *i += 1;
            }
            if *i < s.len() && s[*i] == '{' {
                *i += 1;
                loop {
                    tree(s, i, path.clone(), out);
                    while *i < s.len() && s[*i] == ' ' {
                        *i += 1;
                    }
                    match s.get(*i) {
                        Some(',') => *i += 1,
                        Some('}') => {
                            *i += 1;
                            return;
                        }
                        _ => return,
                    }
                    while *i < s.len() && s[*i] == ' ' {
                        *i += 1;
                    }
                    if s.get(*i) == Some(&'}') {
                        *i += 1;
                        return;
                    }
                }
            }
            let start = *i;
            while *i < s.len() && (s[*i].is_ascii_alphanumeric() || s[*i] == '_' || s[*i] == '*') {
                *i += 1;
            }
            if *i > start {
                path.push(s[start..*i].iter().collect());
            }
            if s.get(*i) == Some(&':') && s.get(*i + 1) == Some(&':') {
                *i += 2;
                continue;
            }
            // Skip `as name`.
            out.push(path);
            return;
        }
    }
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    tree(&chars, &mut 0, Vec::new(), &mut out);
    out
}

/// File -> the files its code names, the file-level import graph of one crate's `src` (comments
/// and test modules left out): `crate::a::b`, `super::x`, a child module's `x::`, and for the
/// CLI's binary `voxsplat_cli::a`. A path names the file of its longest module prefix. A file's
/// own ancestors are not counted (a module and the files it declares are one unit: `use super::`
/// into the parent, `pub use child::Item` out of it); every other edge is. The binary's modules
/// (`main.rs` and what it declares) are keyed apart as "bin:".
fn file_graph(root: &Path, lib_name: Option<&str>) -> BTreeMap<String, BTreeSet<String>> {
    let files = rust_files(root);
    let bin_files: BTreeSet<String> = match std::fs::read_to_string(root.join("main.rs")) {
        Ok(main) => main
            .lines()
            .filter_map(|l| l.trim().strip_prefix("mod ").map(|m| m.trim_end_matches(';').to_string()))
            .chain(["main".to_string()])
            .collect(),
        Err(_) => BTreeSet::new(),
    };
    // File key and module path (`src/cpu/mod.rs` -> "cpu/mod", [cpu]).
    let module = |f: &Path| -> (String, bool, Vec<String>) {
        let rel = f.strip_prefix(root).unwrap().with_extension("").to_str().unwrap().to_string();
        if bin_files.contains(&rel) {
            let m = if rel == "main" { vec![] } else { vec![rel.clone()] };
            return (format!("bin:{rel}"), true, m);
        }
        let mut parts: Vec<String> = rel.split('/').map(str::to_string).collect();
        if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
            parts.pop();
        }
        (rel, false, parts)
    };
    let mut lib_mods: BTreeMap<Vec<String>, String> = BTreeMap::new();
    let mut bin_mods: BTreeMap<Vec<String>, String> = BTreeMap::new();
    for f in &files {
        let (k, bin, m) = module(f);
        if bin { &mut bin_mods } else { &mut lib_mods }.insert(m, k);
    }
    let resolve = |mods: &BTreeMap<Vec<String>, String>, path: &[String]| -> Option<(Vec<String>, String)> {
        (0..=path.len()).rev().find_map(|n| mods.get(&path[..n]).map(|k| (path[..n].to_vec(), k.clone())))
    };
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let (k, bin, me) = module(f);
        let mods = if bin { &bin_mods } else { &lib_mods };
        // The code on one line: comments and test modules out.
        let mut code = String::new();
        let mut skip_to: Option<i32> = None;
        let mut depth = 0i32;
        let mut inline = Vec::new();
        let mut test_next = false;
        for line in std::fs::read_to_string(f).unwrap().lines() {
            let c = line.split("//").next().unwrap();
            let opens_mod = c.trim_start().trim_start_matches("pub ").starts_with("mod ") && c.contains('{');
            if skip_to.is_none() && test_next && opens_mod {
                skip_to = Some(depth);
            }
            test_next = c.contains("#[cfg(test)]") || (test_next && c.trim().starts_with("#["));
            if skip_to.is_none() && opens_mod {
                inline.push(depth);
                code.push_str(" \u{1} ");
            }
            depth += c.matches('{').count() as i32 - c.matches('}').count() as i32;
            if skip_to.is_none() {
                code.push_str(c);
                code.push(' ');
            }
            if skip_to.is_some_and(|d| depth <= d) {
                skip_to = None;
            }
            while inline.last().is_some_and(|&d| depth <= d) {
                inline.pop();
                code.push_str(" \u{2} ");
            }
        }
        let children: BTreeSet<String> = mods
            .keys()
            .filter(|m| m.len() == me.len() + 1 && m.starts_with(&me))
            .map(|m| m.last().unwrap().clone())
            .collect();
        let uses = graph.entry(k.clone()).or_default();
        let mut in_inline = 0;
        let bytes: Vec<char> = code.chars().collect();
        let mut i = 0;
        while i < bytes.len() {
            match bytes[i] {
                '\u{1}' => in_inline += 1,
                '\u{2}' => in_inline -= 1,
                _ => {}
            }
            let boundary =
                i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == '_' || bytes[i - 1] == ':');
            if !boundary || !(bytes[i].is_ascii_lowercase() || bytes[i] == '_') {
                i += 1;
                continue;
            }
            let rest: String = bytes[i..].iter().take(400).collect();
            let mut hit = |prefix: &str, base: Vec<String>, table: &BTreeMap<Vec<String>, String>| -> bool {
                let Some(after) = rest.strip_prefix(prefix) else { return false };
                for p in path_tree(after) {
                    let mut full = base.clone();
                    full.extend(p);
                    if let Some((m, t)) = resolve(table, &full) {
                        let ancestor = std::ptr::eq(table, mods) && me.starts_with(&m);
                        if !ancestor && t != k {
                            uses.insert(t);
                        }
                    }
                }
                true
            };
            let parent = me[..me.len().saturating_sub(1)].to_vec();
            let _ = hit("crate::", vec![], mods)
                || (in_inline == 0 && hit("super::", parent, mods))
                || lib_name.is_some_and(|l| hit(&format!("{l}::"), vec![], &lib_mods))
                || children.iter().any(|c| hit(&format!("{c}::"), [me.clone(), vec![c.clone()]].concat(), mods));
            i += 1;
        }
    }
    graph
}

/// The files of `graph` on an import loop.
fn file_loops(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    graph.keys().filter(|f| reaches(graph, f, f)).cloned().collect()
}

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let core = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), None);
    let cli = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("cli/src"), Some("voxsplat_cli"));
    let lab = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("lab/src"), Some("voxsplat_lab"));
    assert!(
        core.len() > 60 && cli.len() > 10 && lab.len() > 10,
        "files found: {} {} {}",
        core.len(),
        cli.len(),
        lab.len()
    );
    let show = |g: &BTreeMap<String, BTreeSet<String>>, on: &[String]| -> String {
        on.iter()
            .map(|f| format!("\n  {f} -> {:?}", g[f].iter().filter(|t| on.contains(t)).collect::<Vec<_>>()))
            .collect()
    };
    let (a, b, c) = (file_loops(&core), file_loops(&cli), file_loops(&lab));
    assert!(
        a.is_empty() && b.is_empty() && c.is_empty(),
        "files on an import loop:{}{}{}",
        show(&core, &a),
        show(&cli, &b),
        show(&lab, &c)
    );
}

#[test]
fn the_vulkan_engine_the_recording_and_the_plan_import_no_mirror() {
    let core = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), None);
    let engine_or_plan = |f: &str| {
        ["gpu/", "vk/", "recording", "plan", "slab", "raster"]
            .iter()
            .any(|p| f == p.trim_end_matches('/') || f.starts_with(p))
    };
    assert!(core.keys().filter(|f| engine_or_plan(f)).count() >= 20, "{:?}", core.keys());
    for (file, uses) in core.iter().filter(|(f, _)| engine_or_plan(f)) {
        let mirrors: Vec<_> = uses.iter().filter(|t| t.starts_with("cpu/") || *t == "cpu_engine").collect();
        assert!(mirrors.is_empty(), "{file} imports the CPU mirrors {mirrors:?}");
    }
}

#[test]
fn the_formats_import_no_study() {
    let core = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), None);
    let formats = ["loaders", "scene", "terrain", "classify", "output", "orient"];
    let studies = ["truth", "metrics", "aa", "animate", "distributed", "bisect"];
    let mut checked = 0;
    for (file, uses) in core.iter().filter(|(f, _)| formats.iter().any(|m| f == m || f.starts_with(&format!("{m}/")))) {
        let reached: Vec<_> =
            uses.iter().filter(|t| studies.iter().any(|s| t == s || t.starts_with(&format!("{s}/")))).collect();
        assert!(reached.is_empty(), "{file} imports the studies {reached:?}");
        checked += 1;
    }
    assert!(checked >= 10, "format files found: {checked}");
}

/// The maths (camera, kernel, order, the volume and its bricks) imports no GPU layout. One
/// exception is left, named here so that it cannot grow: `SplatSet` holds its voxels as the GPU's
/// `Splat` records, uploaded as they are.
#[test]
fn the_maths_imports_no_gpu_layout() {
    let core = file_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), None);
    let maths = ["camera", "kernel", "order", "volume", "bricks"];
    let allowed = [("volume", "gpu_types")];
    let mut checked = 0;
    for (file, uses) in core.iter().filter(|(f, _)| maths.iter().any(|m| f == m || f.starts_with(&format!("{m}/")))) {
        for t in uses.iter().filter(|t| *t == "gpu_types" || t.starts_with("gpu/") || t.starts_with("vk/")) {
            assert!(allowed.contains(&(file.as_str(), t.as_str())), "{file} imports the GPU layout ({t})");
        }
        checked += 1;
    }
    assert!(checked >= 7, "maths files found: {checked}");
}

/// One name, four places: every stage of the table has its shader (`glsl/<name>.comp`, or `.vert`
/// and `.frag` for a draw) and its mirror file (`src/cpu/<name>.rs`, whose `stage` the table's
/// `stages!` declaration names: a missing mirror file already fails to compile).
#[test]
fn every_stage_has_its_shader_and_a_mirror_file_of_its_name() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = std::fs::read_to_string(root.join("src/stages.rs")).unwrap();
    assert!(crate::stages::STAGES.len() >= 26);
    for desc in crate::stages::STAGES {
        let name = desc.name;
        let comp = root.join(format!("glsl/{name}.comp")).exists();
        let draw = root.join(format!("glsl/{name}.vert")).exists() && root.join(format!("glsl/{name}.frag")).exists();
        assert!(comp || draw, "{name}: no glsl/{name}.comp (or .vert and .frag)");
        let mirror = std::fs::read_to_string(root.join(format!("src/cpu/{name}.rs")))
            .unwrap_or_else(|_| panic!("{name}: no mirror file src/cpu/{name}.rs"));
        assert!(mirror.contains("pub(crate) fn stage("), "src/cpu/{name}.rs defines no stage entry");
        assert!(table.contains(&format!("\n    {name} => ")), "stages.rs declares no row for {name}");
    }
}

/// Plan first, then record: past `record_frame` (which makes the plan), no function of the
/// recording takes the render options; it reads the plan and the counts the device reads back.
#[test]
fn the_recording_reads_the_plan_not_the_options() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = vec![root.join("recording.rs")];
    files.extend(rust_files(&root.join("recording")));
    assert!(files.len() >= 3, "{files:?}");
    let mut functions = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (i, _) in text.match_indices("fn ") {
            let signature = &text[i..i + text[i..].find('{').unwrap_or(text.len() - i)];
            let name = signature[3..].split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap();
            functions += 1;
            if signature.contains("RenderOptions") {
                assert_eq!(name, "record_frame", "{}: `{name}` takes the render options", f.display());
            }
        }
    }
    assert!(functions > 20, "functions read: {functions}");
}

/// A small public face: the top level holds what an embedder calls; the engine's parts are
/// private modules reached through `low_level`; the research modules need the `lab` feature.
#[test]
fn the_top_level_holds_the_embedders_modules() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(root.join("lib.rs")).unwrap();
    let embedder = [
        "animate",
        "bricks",
        "camera",
        "classify",
        // What the device reports and what voxsplat chooses from it (`vk::Context::choices`).
        "device",
        "distributed",
        "embedding",
        "image",
        "kernel",
        "labels",
        "loaders",
        "low_level",
        "options",
        "order",
        "orient",
        "output",
        "scene",
        "terrain",
        "vk",
        "volume",
    ];
    let lab = ["aa", "metrics", "truth"];
    let lines: Vec<&str> = lib.lines().collect();
    let mut public = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let Some(rest) = l.strip_prefix("pub mod ") else { continue };
        let name = rest.split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap();
        if lab.contains(&name) {
            assert_eq!(lines[i - 1].trim(), "#[cfg(feature = \"lab\")]", "{name} needs the lab feature");
        } else {
            assert!(embedder.contains(&name), "`pub mod {name}` at the top level: an engine part goes in low_level");
        }
        public.push(name);
    }
    assert!(public.len() >= 15 && public.len() <= embedder.len() + lab.len(), "{public:?}");
    // low_level names its items one by one (no glob, no module), at most 30: what the CLI and the
    // lab reach below the facade, not the engine; the engine's tests use the internals from inside
    // the crate. Its re-exports come from modules private at the top, so each has one path.
    let low = std::fs::read_to_string(root.join("low_level.rs")).unwrap();
    assert!(!low.contains("::*"), "low_level re-exports a module whole: name its items");
    assert!(!low.contains("pub mod "), "low_level holds a module: name the items the lab needs");
    let mut items = Vec::new();
    let code: String = low.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n");
    for (i, _) in code.match_indices("pub use crate::") {
        let m = code[i + 15..].split("::").next().unwrap();
        assert!(lines.contains(&format!("mod {m};").as_str()), "{m}: low_level's module is private at the top");
        let rest = &code[i + 15..code[i..].find(';').unwrap() + i];
        let names = rest.rsplit("::").next().unwrap().trim_matches(|c| c == '{' || c == '}');
        items.extend(names.split(',').map(|n| n.trim().to_string()).filter(|n| !n.is_empty()));
    }
    for l in code.lines() {
        for kind in ["pub fn ", "pub struct ", "pub enum ", "pub const ", "pub trait "] {
            if let Some(r) = l.strip_prefix(kind) {
                items.push(r.split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap().to_string());
            }
        }
    }
    assert!((8..=30).contains(&items.len()), "low_level lists {} items: {items:?}", items.len());
    // Test probes are not methods of Renderer: no hidden public method on it.
    for f in ["lib.rs", "series.rs", "animate.rs"] {
        let code = std::fs::read_to_string(root.join(f)).unwrap();
        assert!(
            !code.contains("#[doc(hidden)]\n    pub fn"),
            "{f}: a hidden Renderer method (a probe goes in low_level)"
        );
    }
}

/// The facade an embedder reads in one sitting: at most 40 public names at the top (modules,
/// types, functions), each with a doc example; all else has one path, in its module.
#[test]
fn the_facade_has_at_most_forty_names_each_with_an_example() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    let lib = read(&src.join("lib.rs"));
    let lines: Vec<&str> = lib.lines().collect();
    // The doc lines (and attributes) right above line `i` of `lines` hold an example: a code block,
    // in the comment or in the file an attribute includes.
    let example_above = |lines: &[&str], i: usize, dir: &Path| {
        let mut j = i;
        while j > 0 && (lines[j - 1].trim_start().starts_with("///") || lines[j - 1].trim_start().starts_with("#[")) {
            j -= 1;
            let l = lines[j];
            if l.contains("```") {
                return true;
            }
            if let Some(f) = l.split("include_str!(\"").nth(1).and_then(|r| r.split('"').next()) {
                if read(&dir.join(f)).contains("```") {
                    return true;
                }
            }
        }
        false
    };
    let defined_with_example = |module: &str, name: &str| {
        // The module's file, or one of its submodules' (`options::Rendered` is in options/stats.rs).
        let mut files = vec![src.join(format!("{module}.rs"))];
        files.extend(std::fs::read_dir(src.join(module)).into_iter().flatten().flatten().map(|e| e.path()));
        files.iter().any(|f| {
            let text = read(f);
            let lines: Vec<&str> = text.lines().collect();
            lines.iter().enumerate().any(|(i, l)| {
                ["pub struct ", "pub enum ", "pub type ", "pub fn ", "pub trait "].iter().any(|k| {
                    l.strip_prefix(k).is_some_and(|r| {
                        r.starts_with(name) && !r[name.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
                    })
                }) && example_above(&lines, i, &src)
            })
        })
    };
    let mut names: Vec<(String, bool)> = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        if let Some(r) = l.strip_prefix("pub mod ") {
            let name = r.split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap();
            let file = [src.join(format!("{name}.rs")), src.join(name).join("mod.rs")].into_iter().find(|p| p.exists());
            let header: String =
                file.map(|f| read(&f)).unwrap_or_default().lines().take_while(|l| l.starts_with("//!")).collect();
            names.push((name.to_string(), header.contains("```") || example_above(&lines, i, &src)));
        } else if let Some(r) = l.strip_prefix("pub use ") {
            let r = r.trim_end_matches(';');
            let (module, list) = r.split_once("::").unwrap_or(("", r));
            for n in list.trim_matches(|c| c == '{' || c == '}').split(',').map(str::trim).filter(|n| !n.is_empty()) {
                names.push((n.to_string(), example_above(&lines, i, &src) || defined_with_example(module, n)));
            }
        } else {
            for k in ["pub struct ", "pub enum ", "pub fn ", "pub type ", "pub trait ", "pub const "] {
                if let Some(r) = l.strip_prefix(k) {
                    let n = r.split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap();
                    names.push((n.to_string(), example_above(&lines, i, &src)));
                }
            }
        }
    }
    let all: Vec<&str> = names.iter().map(|(n, _)| n.as_str()).collect();
    assert!((10..=40).contains(&names.len()), "{} names at the top: {all:?}", names.len());
    let bare: Vec<&str> = names.iter().filter(|(_, e)| !e).map(|(n, _)| n.as_str()).collect();
    assert!(bare.is_empty(), "top-level names without a doc example: {bare:?}");
}

/// The crates the core's modules will move to (docs/DEVELOPING.md, "The crates to come"), each
/// with the crates it may import: Cargo will refuse an import that runs up; until then this test
/// does. The facade (`lib.rs`, `low_level`, `animate`, `series`, `distributed`) may import all.
const CRATES: [(&str, &[&str], &[&str]); 5] = [
    (
        "model",
        &[
            "error",
            "constants",
            "volume",
            "camera",
            "kernel",
            "classify",
            "labels",
            "orient",
            "order",
            "options",
            "image",
            "kdtree",
            "residency",
            "bricks",
            "gpu_types",
            "iso",
            "device",
            "resample",
        ],
        &["model"],
    ),
    ("vk", &["vk"], &["vk", "model"]),
    ("io", &["loaders", "output", "terrain", "scene"], &["io", "model"]),
    (
        "engine",
        &[
            "stages",
            "builds",
            "plan",
            "recording",
            "cpu",
            "cpu_engine",
            "dispatch",
            "shaders",
            "gpu",
            "raster",
            "pick",
            "bisect",
            "bands",
        ],
        &["engine", "model", "vk"],
    ),
    ("reference", &["truth", "metrics", "aa"], &["reference", "model"]),
];

/// The imports that still run up a layer, each to be cut before the crates move (the test fails
/// when one is cut and still listed, so the list only shrinks).
const STILL_UP: [(&str, &str); 1] = [
    // BrickStore::load and the streamed build read files (loaders' SliceReader): into io.
    ("bricks", "loaders"),
];

/// Module -> the modules it names as `crate::x` or through a name the crate root re-exports
/// (`crate::Camera` is `camera`'s), test modules included.
fn module_graph_with_root_names() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    // `pub use m::{A, B};` and `pub use m::A;` at the root.
    let mut root: BTreeMap<String, String> = BTreeMap::new();
    for stmt in lib.split(';') {
        let Some(rest) = stmt.trim().strip_prefix("pub use ") else { continue };
        let Some((module, names)) = rest.split_once("::") else { continue };
        for name in names.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).filter(|n| !n.is_empty()) {
            root.insert(name.to_string(), module.to_string());
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in rust_files(&src) {
        let rel = f.strip_prefix(&src).unwrap().to_str().unwrap().trim_end_matches(".rs").to_string();
        let top = rel.split('/').next().unwrap().to_string();
        let uses = graph.entry(top.clone()).or_default();
        for line in std::fs::read_to_string(&f).unwrap().lines() {
            let code = line.split("//").next().unwrap();
            for (i, _) in code.match_indices("crate::") {
                let name: String =
                    code[i + 7..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                let module = if name.starts_with(|c: char| c.is_ascii_uppercase()) {
                    root.get(&name).cloned()
                } else {
                    Some(name)
                };
                if let Some(m) = module.filter(|m| *m != top) {
                    uses.insert(m);
                }
            }
        }
    }
    graph
}

#[test]
fn no_module_imports_a_layer_above_the_crate_it_will_move_to() {
    let graph = module_graph_with_root_names();
    let crate_of = |m: &str| CRATES.iter().find(|c| c.1.contains(&m)).map(|c| c.0);
    let facade = ["lib", "low_level", "animate", "series", "distributed", "embedding"];
    for m in graph.keys().filter(|m| !facade.contains(&m.as_str())) {
        assert!(crate_of(m).is_some(), "module {m} has no crate in CRATES");
    }
    let mut up = Vec::new();
    for (from, uses) in &graph {
        let Some(c) = crate_of(from) else { continue };
        let may = CRATES.iter().find(|x| x.0 == c).unwrap().2;
        for to in uses {
            let Some(d) = crate_of(to) else {
                assert!(!facade.contains(&to.as_str()), "{from} ({c}) imports the facade's {to}");
                continue;
            };
            if !may.contains(&d) {
                up.push((from.as_str(), to.as_str()));
            }
        }
    }
    assert_eq!(up, STILL_UP, "imports that run up a layer (from, to)");
    // The ash layer takes no render options and no camera.
    for f in rust_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src/vk")) {
        for line in std::fs::read_to_string(&f).unwrap().lines() {
            let code = line.split("//").next().unwrap();
            for name in ["RenderOptions", "Camera"] {
                assert!(!code.contains(name), "{} names {name}: {line}", f.display());
            }
        }
    }
}
