//! Stamps the binary with the commit it was built from (`VERGEN_GIT_SHA`, `VERGEN_GIT_DIRTY`), which
//! every training process records in its run's `provenance.jsonl` (src/provenance.rs); with the
//! `cuda` feature, links libtorch's CUDA library into the binary; with `SEADS_TEST_SLURM=1`,
//! builds the Slurm test.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The full SHA; dirty counts tracked files only. vergen reruns this script when HEAD moves;
    // an edit to any source of the binary must rerun it too, or a rebuild would call itself clean.
    // Each crate's sources and manifest only: generated files elsewhere under crates/ (the
    // Python package's build outputs) must not rerun it.
    for entry in std::fs::read_dir("../../crates")? {
        let dir = entry?.path();
        for part in ["src", "Cargo.toml"] {
            println!("cargo:rerun-if-changed={}", dir.join(part).display());
        }
    }
    for file in ["../../Cargo.toml", "../../Cargo.lock"] {
        println!("cargo:rerun-if-changed={file}");
    }
    let git = vergen_gitcl::GitclBuilder::default()
        .sha(false)
        .dirty(false)
        .build()?;
    // Outside a git checkout (a crates.io download) vergen emits its default and a warning.
    vergen_gitcl::Emitter::default()
        .add_instructions(&git)?
        .emit()?;
    // Tests that need what a machine may lack are switched on explicitly: the Slurm test is
    // built only with SEADS_TEST_SLURM=1 (tests/end_to_end/slurm.rs).
    println!("cargo::rustc-check-cfg=cfg(seads_test_slurm)");
    println!("cargo:rerun-if-env-changed=SEADS_TEST_SLURM");
    if std::env::var("SEADS_TEST_SLURM").as_deref() == Ok("1") {
        println!("cargo:rustc-cfg=seads_test_slurm");
    }
    // tch registers CUDA through the static initialisers of libtorch_cuda.so, of which no symbol
    // is used: the linker's default `--as-needed` would drop it, and CUDA would then be absent.
    // Only the binaries get the flag (a build script linked with it would fail where the CUDA
    // libraries are not installed).
    if std::env::var_os("CARGO_FEATURE_CUDA").is_some() {
        println!("cargo:rustc-link-arg-bins=-Wl,--no-as-needed,-ltorch_cuda,--as-needed");
    }
    Ok(())
}
