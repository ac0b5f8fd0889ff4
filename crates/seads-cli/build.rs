//! Stamps the binary with the commit it was built from (`VERGEN_GIT_SHA`, `VERGEN_GIT_DIRTY`), which
//! every training process records in its run's `provenance.jsonl` (src/provenance.rs).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The full SHA; dirty counts tracked files only (as of the last build script run).
    let git = vergen_gitcl::GitclBuilder::default()
        .sha(false)
        .dirty(false)
        .build()?;
    // Outside a git checkout (a crates.io download) vergen emits its default and a warning.
    vergen_gitcl::Emitter::default()
        .add_instructions(&git)?
        .emit()?;
    Ok(())
}
