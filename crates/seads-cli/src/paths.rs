//! Paths a command is given: an output must not be one of its inputs.

use std::os::unix::fs::MetadataExt as _;
use std::path::Path;

use anyhow::{Result, anyhow};

use crate::BadInput;

/// The user's input to fix: exit 2 with `message`.
fn invalid(message: String) -> anyhow::Error {
    BadInput(anyhow!(message)).into()
}

/// Refuses an output path that is one of the command's inputs (the same file or folder, through
/// any path or link), as the user's input to fix: an output never overwrites what the command
/// reads. A path that does not exist yet overwrites nothing.
pub fn refuse_overwriting_input(output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::metadata(output) else {
        return Ok(());
    };
    for input in inputs {
        if let Ok(meta) = std::fs::metadata(input)
            && (meta.dev(), meta.ino()) == (out.dev(), out.ino())
        {
            return Err(invalid(format!(
                "{} is also an input ({}): an output never overwrites its input",
                output.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// Refuses an output path that would damage something (the user's input to fix, before anything
/// is written): one that exists and is not a regular file (a device, a FIFO, a symlink, a
/// folder: outputs are written only as regular files, by renaming a finished file into place,
/// never onto a special file or a link's target), one inside a folder the command reads (a run
/// directory given as its agent), or one of its inputs ([`refuse_overwriting_input`]).
pub fn refuse_unsafe_output(output: &Path, inputs: &[&Path]) -> Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(output)
        && !meta.file_type().is_file()
    {
        let kind = if meta.file_type().is_symlink() {
            "a symbolic link"
        } else if meta.is_dir() {
            "a folder"
        } else {
            "a special file"
        };
        return Err(invalid(format!(
            "{} is {kind}: an output replaces only a regular file",
            output.display()
        )));
    }
    let parent = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if let Ok(parent) = std::fs::canonicalize(parent) {
        for input in inputs {
            if let Ok(input) = std::fs::canonicalize(input)
                && input.is_dir()
                && parent.starts_with(&input)
            {
                return Err(invalid(format!(
                    "{} lies inside {}, which this command reads: write it elsewhere",
                    output.display(),
                    input.display()
                )));
            }
        }
    }
    refuse_overwriting_input(output, inputs)
}

/// Checks an output file before any work is done for it: [`refuse_unsafe_output`], a name that
/// ends in one of `extensions` (the formats the command writes), and a folder for it that exists.
/// Each failure is the user's input to fix, said in one line that names the path.
pub fn check_output_file(output: &Path, inputs: &[&Path], extensions: &[&str]) -> Result<()> {
    refuse_unsafe_output(output, inputs)?;
    let known = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| x.eq_ignore_ascii_case(e)));
    if !known {
        return Err(invalid(format!(
            "{}: the output must be a .{} file",
            output.display(),
            extensions.join(", .")
        )));
    }
    let parent = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(invalid(format!(
            "{}: the folder {} does not exist",
            output.display(),
            parent.display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_that_is_an_input_through_a_link_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let input = tmp.path().join("in.json");
        std::fs::write(&input, "{}").unwrap();
        let link = tmp.path().join("link.json");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let e = refuse_overwriting_input(&link, &[&input]).unwrap_err();
        assert!(
            e.downcast_ref::<BadInput>().is_some() && e.to_string().contains("also an input"),
            "{e}"
        );
        assert!(refuse_overwriting_input(&tmp.path().join("new.json"), &[&input]).is_ok());
        std::fs::write(tmp.path().join("other.json"), "{}").unwrap();
        assert!(refuse_overwriting_input(&tmp.path().join("other.json"), &[&input]).is_ok());
    }

    #[test]
    fn special_files_links_and_outputs_inside_an_input_are_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let run = tmp.path().join("run");
        std::fs::create_dir(&run).unwrap();
        std::fs::write(run.join("config.toml"), "env = 1").unwrap();
        let target = tmp.path().join("target.json");
        std::fs::write(&target, "{}").unwrap();
        let link = tmp.path().join("link.json");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let refused = |out: &Path, inputs: &[&Path], why: &str| {
            let e = refuse_unsafe_output(out, inputs).unwrap_err();
            assert!(
                e.downcast_ref::<BadInput>().is_some() && e.to_string().contains(why),
                "{e}"
            );
        };
        refused(&link, &[], "a symbolic link");
        refused(&run, &[], "a folder");
        refused(Path::new("/dev/null"), &[], "a special file");
        refused(&run.join("config.toml"), &[&run], "inside");
        refused(&run.join("new.json"), &[&run], "inside");
        assert!(refuse_unsafe_output(&tmp.path().join("new.json"), &[&run]).is_ok());
        assert!(
            refuse_unsafe_output(&target, &[&run]).is_ok(),
            "a regular file is replaced"
        );
    }
}
