//! Doc-tests run from temporary folders, where the `$ORIGIN`-relative rpath of
//! `.cargo/config.toml` cannot reach the workspace's libtorch (`scripts/setup.sh`). Cargo hands a
//! build script's link arguments to this crate's tests, examples and doc-tests: this one gives
//! them the absolute path, so `cargo test` runs them as typed. Outside the workspace (a
//! packaged crate) there is no such folder and nothing is added.

#![allow(clippy::print_stdout)] // a build script talks to cargo on stdout

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default();
    let lib = std::path::Path::new(&manifest).join("../../.libtorch/lib");
    if let Ok(lib) = lib.canonicalize() {
        println!("cargo:rerun-if-changed={}", lib.display());
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
    }
}
