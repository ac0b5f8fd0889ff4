//! The shipped presets (`configs/`, embedded by `build.rs`).

use seads_run::TrainConfig;

/// The presets are found by file name: every file of `configs/` is embedded in the table of its
/// algorithm (`sac-`, `hac-` or none) under the environment the rest of its name gives, with the
/// file's text; and each trains that environment with that algorithm.
#[test]
fn every_preset_file_is_embedded_under_its_name() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut files = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap();
        let stem = name.strip_suffix(".toml").unwrap();
        let (table, env, algorithm) = match stem.split_once('-') {
            Some(("sac", env)) => (TrainConfig::sac_presets(), env, "sac"),
            Some(("hac", env)) => (TrainConfig::hac_presets(), env, "hac"),
            _ => (TrainConfig::presets(), stem, "seads"),
        };
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            table.iter().any(|(e, t)| *e == env && *t == text),
            "{name} is embedded as {env}'s {algorithm} preset"
        );
        let config = TrainConfig::from_toml(&text).unwrap();
        assert_eq!(
            (config.env.as_str(), config.algorithm().name()),
            (env, algorithm),
            "{name}"
        );
        files += 1;
    }
    let embedded = TrainConfig::presets().len()
        + TrainConfig::sac_presets().len()
        + TrainConfig::hac_presets().len();
    assert_eq!(embedded, files, "nothing embedded but the files");
}
