//! Paths a command is given: an output must not be one of its inputs.

use std::os::unix::fs::MetadataExt as _;
use std::path::Path;

use crate::{Result, StudyError};

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
            return Err(StudyError::invalid(format!(
                "{} is also an input ({}): an output never overwrites its input",
                output.display(),
                input.display()
            )));
        }
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
            e.is_invalid() && e.to_string().contains("also an input"),
            "{e}"
        );
        assert!(refuse_overwriting_input(&tmp.path().join("new.json"), &[&input]).is_ok());
        std::fs::write(tmp.path().join("other.json"), "{}").unwrap();
        assert!(refuse_overwriting_input(&tmp.path().join("other.json"), &[&input]).is_ok());
    }
}
