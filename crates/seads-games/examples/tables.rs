//! Writes the depth and split tables (`depth_counts.csv`, `split_counts.csv`: SPEC §1.3, §1.4)
//! into a folder, from a fresh enumeration; `cargo xtask gen-splits` runs it for `data/`, and
//! `tests/tables.rs` checks that the committed tables are what it writes.
//!
//! ```sh
//! cargo run --release -p seads-games --example tables -- data
//! ```
#![allow(clippy::print_stderr)] // an example says what it wrote

use std::io::Write as _;
use std::path::Path;

use seads_games::tables::{depth_counts_csv, split_counts_csv};

/// Writes `text` to `path` whole or not at all (temporary file, fsync, rename, the folder fsynced).
fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let mut file = atomic_write_file::AtomicWriteFile::open(path)?;
    file.write_all(text.as_bytes())?;
    file.commit()
}

fn main() -> std::io::Result<()> {
    let Some(folder) = std::env::args_os().nth(1) else {
        eprintln!(
            "usage: tables FOLDER (writes FOLDER/depth_counts.csv and FOLDER/split_counts.csv)"
        );
        std::process::exit(2);
    };
    let folder = Path::new(&folder);
    std::fs::create_dir_all(folder)?;
    for (name, csv) in [
        ("depth_counts.csv", depth_counts_csv()),
        ("split_counts.csv", split_counts_csv()),
    ] {
        let path = folder.join(name);
        write_atomically(&path, &csv)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

#[test]
fn a_table_is_written_whole_over_the_old_one_and_no_temporary_file_stays() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("depth_counts.csv");
    std::fs::write(&path, "old\n").unwrap();
    write_atomically(&path, "game,size,depth,count\n").unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        "game,size,depth,count\n"
    );
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "only the table is left: {names:?}");
}
