//! The presets: every file of `configs/` (`<env>.toml` for SEADS, `sac-<env>.toml` and
//! `hac-<env>.toml` for the baselines) is embedded, found by its name, so that a new
//! environment's preset is a new file and nothing else (`$OUT_DIR/presets.rs`, included by
//! `src/config.rs`).

#![allow(clippy::print_stdout)] // a build script talks to cargo on stdout

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    presets();
}

/// Writes `$OUT_DIR/presets.rs`: one table per algorithm of `(environment, TOML text)`, sorted by
/// environment, every `configs/*.toml` in one of them by its name.
fn presets() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = std::path::Path::new(&manifest).join("configs");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut tables: [(&str, Vec<(String, String)>); 3] = [
        ("PRESETS", vec![]),
        ("SAC_PRESETS", vec![]),
        ("HAC_PRESETS", vec![]),
    ];
    let entries = std::fs::read_dir(&dir).expect("crates/seads-run/configs holds the presets");
    for entry in entries {
        let path = entry.expect("a readable configs folder").path();
        let Some(stem) = path
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_suffix(".toml"))
        else {
            continue;
        };
        let (table, env) = match stem.split_once('-') {
            Some(("sac", env)) => (1, env),
            Some(("hac", env)) => (2, env),
            _ => (0, stem),
        };
        tables[table]
            .1
            .push((env.to_owned(), path.display().to_string()));
    }
    let mut code = String::from("// Written by build.rs from the files of configs/.\n");
    for (name, mut entries) in tables {
        entries.sort();
        code += &format!("const {name}: &[(&str, &str)] = &[\n");
        for (env, path) in entries {
            code += &format!("    ({env:?}, include_str!({path:?})),\n");
        }
        code += "];\n";
    }
    let out = std::path::Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
        .join("presets.rs");
    std::fs::write(out, code).expect("OUT_DIR is writable");
}
