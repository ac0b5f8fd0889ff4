//! The presets: every file of `configs/` is embedded, found by its path, so that a new
//! environment's, game's, manipulator's or learner's preset is a new file and nothing else
//! (`$OUT_DIR/presets.rs`, included by `src/config.rs`, which lays the layers together):
//! - `configs/<layer>.toml`: SEADS's layer of a manipulator (`cursor`), a game (`sliding`) or an
//!   environment (`uarm-lightsout-absolute`);
//! - `configs/<algorithm>/<layer>.toml`: another learner's layer of the same kinds;
//! - `configs/<algorithm>/every-env.toml`: a learner's settings on every environment.

#![allow(clippy::print_stdout)] // a build script talks to cargo on stdout

use std::path::{Path, PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    presets();
}

/// Writes `$OUT_DIR/presets.rs`: `PRESETS`, every `(algorithm, layer, TOML text)`, sorted; a
/// learner's settings on every environment have the layer `*`.
fn presets() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = Path::new(&manifest).join("configs");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut entries: Vec<(String, String, String)> = vec![];
    for (path, algorithm) in toml_files(&dir, "seads") {
        println!("cargo:rerun-if-changed={}", path.display());
        let stem = path
            .file_stem()
            .and_then(|n| n.to_str())
            .expect("a UTF-8 file name");
        let env = if stem == "every-env" { "*" } else { stem };
        entries.push((algorithm, env.to_owned(), path.display().to_string()));
    }
    entries.sort();
    let mut code = String::from("// Written by build.rs from the files of configs/.\n");
    code += "const PRESETS: &[(&str, &str, &str)] = &[\n";
    for (algorithm, env, path) in entries {
        code += &format!("    ({algorithm:?}, {env:?}, include_str!({path:?})),\n");
    }
    code += "];\n";
    let out = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("presets.rs");
    std::fs::write(out, code).expect("OUT_DIR is writable");
}

/// The `.toml` files of `dir` with their algorithm: `algorithm` for the files in `dir` itself,
/// a folder's name for the files in that folder.
fn toml_files(dir: &Path, algorithm: &str) -> Vec<(PathBuf, String)> {
    let mut files = vec![];
    let entries = std::fs::read_dir(dir).expect("crates/seads-run/configs holds the presets");
    for entry in entries {
        let path = entry.expect("a readable configs folder").path();
        if path.is_dir() {
            println!("cargo:rerun-if-changed={}", path.display());
            let name = path
                .file_name()
                .and_then(|n| n.to_str())
                .expect("a UTF-8 folder name");
            files.extend(toml_files(&path, name));
        } else if path.extension().is_some_and(|e| e == "toml") {
            files.push((path, algorithm.to_owned()));
        }
    }
    files
}
