//! Compiles every GLSL shader in `shaders/` to SPIR-V with glslangValidator and
//! generates the table `shaders.rs` that embeds them: each fragment and compute
//! shader twice, as itself and as its fetch-counting build (`NAME#count`,
//! compiled with -DDERMIS_COUNT_FETCHES; see shaders/fetch_count.glsl). The target is SPIR-V 1.0
//! (vulkan1.0 environment): the vendored spirv-reflect misses storage buffers in
//! the StorageBuffer storage class (SPIR-V 1.3+) and cannot parse the SPIR-V 1.4+
//! entry-point interfaces; SPIR-V 1.0 spells SSBOs as Uniform + BufferBlock. A missing compiler stops
//! the build with the name of the Debian package that provides it.
//!
//! Before compiling, it writes `shader_constants.glsl` (the numbers shaders
//! share with Rust, from src/shader_constants.rs, compiled into this script)
//! into OUT_DIR, which is on the include path. After compiling, naga (an
//! independent SPIR-V front end) parses and validates every module, so a
//! glslang quirk stops the build instead of reaching a driver.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The constants shared with the crate: the same file, compiled here too.
#[path = "../src/shader_constants.rs"]
#[allow(dead_code)]
mod shader_constants;

/// Suffix of a shader's fetch-counting build in the table.
const COUNT_SUFFIX: &str = "#count";

fn main() {
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = Path::new("shaders");
    // Headers (*.glsl) are compiled only through the shaders that include them.
    println!("cargo:rerun-if-changed=shaders");
    println!("cargo:rerun-if-changed=src/shader_constants.rs");
    std::fs::write(out.join("shader_constants.glsl"), shader_constants::glsl())
        .expect("writing shader_constants.glsl");
    let include_out = format!("-I{}", out.display());
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("shaders/ directory is missing")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("vert" | "frag" | "comp")
            )
        })
        .collect();
    entries.sort();
    let compiler = std::env::var("GLSLANG_VALIDATOR").unwrap_or_else(|_| "glslangValidator".into());
    let mut table = String::from("/// (file name, SPIR-V bytes) of every shader in shaders/, built by build.rs.\npub static SHADERS: &[(&str, &[u8])] = &[\n");
    for src in &entries {
        println!("cargo:rerun-if-changed={}", src.display());
        let name = src.file_name().unwrap().to_string_lossy().to_string();
        let counted = !name.ends_with(".vert");
        let variants: &[(&str, &[&str])] = if counted {
            &[("", &[]), (COUNT_SUFFIX, &["-DDERMIS_COUNT_FETCHES"])]
        } else {
            &[("", &[])]
        };
        for (suffix, defines) in variants {
            let spv = out.join(format!("{name}{}.spv", suffix.replace('#', "_")));
            let status = Command::new(&compiler)
                .args(["-V", "--target-env", "vulkan1.0", "-Ishaders", &include_out])
                .args(defines.iter())
                .arg("-o")
                .arg(&spv)
                .arg(src)
                .output();
            match status {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => panic!(
                    "glslangValidator not found: install the Debian package glslang-tools (apt-get install glslang-tools), or set GLSLANG_VALIDATOR"
                ),
                Err(e) => panic!("running glslangValidator on {name}: {e}"),
                Ok(o) if !o.status.success() => panic!(
                    "glslangValidator failed on shaders/{name}{suffix}:\n{}{}",
                    String::from_utf8_lossy(&o.stdout),
                    String::from_utf8_lossy(&o.stderr)
                ),
                Ok(_) => {}
            }
            validate(&spv, &format!("{name}{suffix}"));
            writeln!(
                table,
                "    ({:?}, include_bytes!({:?})),",
                format!("{name}{suffix}"),
                spv.display().to_string()
            )
            .unwrap();
        }
    }
    table.push_str("];\n");
    std::fs::write(out.join("shaders.rs"), table).expect("writing shaders.rs");
    embed_data(&out);
}

/// The project's data a command reads, embedded into the binary (issue 27: a
/// binary that runs anywhere): the budget profiles, the measured accuracy
/// tables and the planner's stored frames, as `embedded.rs`'s table of
/// (path under the project, text), sorted by path.
const EMBEDDED: [&str; 3] = ["profiles", "profiles/accuracy", "profiles/frames/plan"];

fn embed_data(out: &Path) {
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in EMBEDDED {
        println!("cargo:rerun-if-changed={dir}");
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("reading {dir}: {e}"));
        for e in entries {
            let p = e.expect("a folder entry").path();
            let data = matches!(
                p.extension().and_then(|x| x.to_str()),
                Some("toml" | "json")
            );
            if p.is_file() && data {
                println!("cargo:rerun-if-changed={}", p.display());
                files.push(p);
            }
        }
    }
    files.sort();
    let root = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let mut table = String::from(
        "/// (path under the project, text) of every data file a command reads, built by build.rs.\npub static FILES: &[(&str, &str)] = &[\n",
    );
    for p in &files {
        let rel = p.to_string_lossy().replace('\\', "/");
        let abs = Path::new(&root).join(p);
        writeln!(
            table,
            "    ({rel:?}, include_str!({:?})),",
            abs.display().to_string()
        )
        .unwrap();
    }
    table.push_str("];\n");
    std::fs::write(out.join("embedded.rs"), table).expect("writing embedded.rs");
}

/// Parses and validates one SPIR-V module with naga; a failure stops the build.
fn validate(spv: &Path, name: &str) {
    let bytes = std::fs::read(spv).unwrap_or_else(|e| panic!("reading {}: {e}", spv.display()));
    let module = naga::front::spv::parse_u8_slice(&bytes, &naga::front::spv::Options::default())
        .unwrap_or_else(|e| panic!("naga cannot parse shaders/{name}: {e:?}"));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("naga rejects shaders/{name}: {e:?}"));
}
