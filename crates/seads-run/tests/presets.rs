//! The shipped presets (`configs/`, embedded by `build.rs`).

use seads_run::TrainConfig;

/// The presets are found by path: every file of `configs/` is embedded under its learner (SEADS
/// for the files of `configs/` itself, the folder's name for those in a folder) and the
/// environment its name gives, with the file's text; and each trains that environment with that
/// learner.
#[test]
fn every_preset_file_is_embedded_under_its_name() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut files = 0;
    let walk = walkdir::WalkDir::new(&dir).sort_by_file_name();
    for entry in walk
        .into_iter()
        .map(Result::unwrap)
        .filter(|e| e.file_type().is_file())
    {
        let path = entry.path();
        let stem = path.file_stem().unwrap().to_str().unwrap();
        // A learner's settings on every environment are embedded under the environment `*`.
        let env = if stem == "every-env" { "*" } else { stem };
        let algorithm = match path.parent().unwrap() {
            parent if parent == dir => "seads",
            parent => parent.file_name().unwrap().to_str().unwrap(),
        };
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            TrainConfig::preset_files()
                .iter()
                .any(|&(a, e, t)| (a, e, t) == (algorithm, env, text.as_str())),
            "{} is embedded as {env}'s {algorithm} preset",
            path.display()
        );
        let config = match env {
            "*" => TrainConfig::preset_for("lightsout-cursor", algorithm).unwrap(),
            _ => TrainConfig::from_toml(&text).unwrap(),
        };
        assert_eq!(config.algorithm(), algorithm, "{}", path.display());
        assert!(env == "*" || config.env == env, "{}", path.display());
        files += 1;
    }
    assert_eq!(
        TrainConfig::preset_files().len(),
        files,
        "nothing embedded but the files"
    );
}
