//! The GPU stages' SPIR-V, and `OUT_DIR/shaders.rs`: per shader a module of its builds, which the
//! stage table names (`src/shaders.rs`).
//!
//! With the `shaderc` feature (development and CI): every GLSL stage in `glsl/` is compiled to
//! OUT_DIR, with `glsl/shared/` as the include directory and the constants of `src/constants.rs`
//! injected as macros; tests/spirv.rs checks the result against the shipped copies (and refreshes
//! them with `VOXSPLAT_BLESS_SPIRV=1`). Without it (a dependent crate): the SPIR-V shipped in
//! `glsl/spirv/` is used as it is, so neither shaderc nor a link override is needed.
use std::path::{Path, PathBuf};

#[allow(dead_code)]
mod constants {
    include!("src/constants.rs");
}

fn main() {
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    println!("cargo:rerun-if-changed=src/constants.rs");
    println!("cargo:rerun-if-changed=glsl");
    #[cfg(feature = "shaderc")]
    let (dir, built) = (out.clone(), compile::compile_all(Path::new("glsl"), &out));
    #[cfg(not(feature = "shaderc"))]
    let (dir, built) = (manifest.join("glsl/spirv"), shipped(&manifest.join("glsl/spirv")));
    let _ = &manifest;
    std::fs::write(out.join("shaders.rs"), shader_modules(&dir, &built)).unwrap();
}

/// `src/shaders.rs`'s body: per shader a module named after it, with one constant per stage kind
/// (`COMP`, `VERT`, `FRAG`: its builds as `(defines, SPIR-V)`) and `SHADERS`, the handle the stage
/// table names (a stage whose shader is missing does not compile); and `SPIRV`, every build by
/// name (`<stage>.<ext>[.<DEFINES>]`) for the check against the shipped copies.
fn shader_modules(dir: &Path, built: &[String]) -> String {
    use std::collections::BTreeMap;
    // Per shader, per stage kind (`comp`, `vert`, `frag`): its builds as (defines, file).
    type Builds<'a> = BTreeMap<&'a str, Vec<(&'a str, &'a str)>>;
    let mut by: BTreeMap<&str, Builds> = BTreeMap::new();
    for name in built {
        let stem = name.strip_suffix(".spv").unwrap();
        let mut parts = stem.splitn(3, '.');
        let (shader, ext) = (parts.next().unwrap(), parts.next().unwrap());
        by.entry(shader).or_default().entry(ext).or_default().push((parts.next().unwrap_or(""), name));
    }
    let mut s = String::new();
    let mut flat = String::from("/// Every SPIR-V build, by name (`<stage>.<ext>[.<DEFINES>]`).\n");
    flat += "pub static SPIRV: &[(&str, &[u8])] = &[\n";
    for (shader, exts) in &by {
        s += &format!("/// `glsl/{shader}.*`'s builds.\npub mod {shader} {{\n");
        for (ext, builds) in exts {
            let konst = ext.to_uppercase();
            s += &format!("    /// `{shader}.{ext}`'s builds: (defines, SPIR-V).\n");
            s += &format!("    pub const {konst}: &[(&str, &[u8])] = &[\n");
            for (i, (defines, file)) in builds.iter().enumerate() {
                let path = dir.join(file).display().to_string();
                s += &format!("        ({defines:?}, include_bytes!({path:?})),\n");
                let dot = if defines.is_empty() { String::new() } else { format!(".{defines}") };
                flat += &format!("    (\"{shader}.{ext}{dot}\", {shader}::{konst}[{i}].1),\n");
            }
            s += "    ];\n";
        }
        let handle = match (exts.contains_key("comp"), exts.contains_key("vert") && exts.contains_key("frag")) {
            (true, false) => "super::Shaders::Compute(COMP)".to_string(),
            (false, true) => "super::Shaders::Draw(VERT, FRAG)".to_string(),
            _ => "super::Shaders::Other".to_string(),
        };
        // The roofline's shaders (a compute and a draw pair) are in no stage table: nothing names
        // their handle.
        let unused = if handle.ends_with("Other") { "    #[allow(dead_code)]\n" } else { "" };
        s += &format!(
            "    /// The handle the stage table names.\n{unused}    pub const SHADERS: super::Shaders = {handle};\n}}\n"
        );
    }
    flat += "];\n";
    s + &flat
}

/// The shipped builds' file names, sorted.
#[cfg(not(feature = "shaderc"))]
fn shipped(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e} (the shipped SPIR-V; build with --features shaderc)", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".spv"))
        .collect();
    names.sort();
    names
}

#[cfg(feature = "shaderc")]
mod compile {
    use super::constants;
    use std::path::{Path, PathBuf};

    /// Compile every stage (and its variants) into `out`; the file names written, sorted.
    pub fn compile_all(glsl: &Path, out: &Path) -> Vec<String> {
        let mut shared: Vec<PathBuf> =
            std::fs::read_dir(glsl.join("shared")).expect("glsl/shared exists").map(|e| e.unwrap().path()).collect();
        shared.sort();
        for p in &shared {
            println!("cargo:rerun-if-changed={}", p.display());
        }
        let mut stages: Vec<PathBuf> =
            std::fs::read_dir(glsl).expect("glsl exists").map(|e| e.unwrap().path()).filter(|p| p.is_file()).collect();
        stages.sort();

        let compiler = shaderc::Compiler::new().expect("shaderc compiler");
        let mut failed = Vec::new();
        let mut built = Vec::new();
        for path in &stages {
            println!("cargo:rerun-if-changed={}", path.display());
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
            let kind = match ext {
                "comp" => shaderc::ShaderKind::Compute,
                "vert" => shaderc::ShaderKind::Vertex,
                "frag" => shaderc::ShaderKind::Fragment,
                _ => continue,
            };
            let source = std::fs::read_to_string(path).unwrap();
            let options = || {
                let mut opts = shaderc::CompileOptions::new().unwrap();
                opts.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
                opts.set_optimization_level(shaderc::OptimizationLevel::Performance);
                opts.set_generate_debug_info();
                for (name, value) in constants::GLSL_DEFINES {
                    opts.add_macro_definition(name, Some(&value.to_string()));
                }
                let shared_dir = glsl.join("shared");
                opts.set_include_callback(move |name, _ty, _from, _depth| {
                    let p = shared_dir.join(name);
                    std::fs::read_to_string(&p)
                        .map(|content| shaderc::ResolvedInclude { resolved_name: p.display().to_string(), content })
                        .map_err(|e| format!("cannot include {}: {e}", p.display()))
                });
                opts
            };
            let file = path.display().to_string();
            let name = path.file_name().unwrap().to_str().unwrap();
            // A stage whose source names `// variants: A B C+D` is also built with each macro (or
            // each `+`-joined set of macros) defined, as `<stage>.A.spv`, `<stage>.C+D.spv` (for code
            // that needs device features the plain build must not, or that holds for some scenes only).
            let variants = source
                .lines()
                .find_map(|l| l.strip_prefix("// variants:"))
                .map(|v| v.split_whitespace().map(str::to_owned).collect::<Vec<_>>())
                .unwrap_or_default();
            for variant in std::iter::once(None).chain(variants.iter().map(Some)) {
                let mut opts = options();
                let out_name = match variant {
                    Some(v) => {
                        for m in v.split('+') {
                            opts.add_macro_definition(m, Some("1"));
                        }
                        format!("{name}.{v}.spv")
                    }
                    None => format!("{name}.spv"),
                };
                match compiler.compile_into_spirv(&source, kind, &file, "main", Some(&opts)) {
                    Ok(art) => {
                        std::fs::write(out.join(&out_name), art.as_binary_u8()).unwrap();
                        built.push(out_name);
                    }
                    // shaderc's message already carries "file:line: error: ...".
                    Err(e) => failed.push(e.to_string()),
                }
            }
        }
        if !failed.is_empty() {
            for f in &failed {
                eprintln!("{f}");
            }
            panic!("GLSL compilation failed:\n{}", failed.join("\n"));
        }
        built.sort();
        built
    }
}
