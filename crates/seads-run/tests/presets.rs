//! The shipped presets (`configs/`, embedded by `build.rs`, laid together by
//! `TrainConfig::preset_for`).

use seads_run::{TrainConfig, learner_names, preset_layers};

/// Every file of `configs/` is embedded under its learner (SEADS for the files of `configs/`
/// itself, the folder's name for those in a folder) and its layer's name, with the file's text;
/// and every layer is laid into some environment's preset, or stands for a game or manipulator
/// (`like`): no file is there for nothing.
#[test]
fn every_preset_file_is_embedded_and_used() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut used: Vec<(String, String)> = vec![];
    for algorithm in learner_names() {
        used.push((algorithm.into(), "*".into()));
        for env in TrainConfig::preset_envs(algorithm) {
            for name in preset_layers(env) {
                used.push((algorithm.into(), name));
            }
            // The parts of the environment's name, where one stands for another.
            for part in env.rsplitn(2, '-') {
                used.push(("seads".into(), part.into()));
            }
        }
    }
    let mut files = 0;
    let walk = walkdir::WalkDir::new(&dir).sort_by_file_name();
    for entry in walk
        .into_iter()
        .map(Result::unwrap)
        .filter(|e| e.file_type().is_file())
    {
        let path = entry.path();
        let stem = path.file_stem().unwrap().to_str().unwrap();
        let name = if stem == "every-env" { "*" } else { stem };
        let algorithm = match path.parent().unwrap() {
            parent if parent == dir => "seads",
            parent => parent.file_name().unwrap().to_str().unwrap(),
        };
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            TrainConfig::preset_files()
                .iter()
                .any(|&(a, n, t)| (a, n, t) == (algorithm, name, text.as_str())),
            "{} is embedded as {algorithm}'s layer {name}",
            path.display()
        );
        assert!(
            used.contains(&(algorithm.to_owned(), name.to_owned())),
            "{} is laid into no preset",
            path.display()
        );
        files += 1;
    }
    assert_eq!(
        TrainConfig::preset_files().len(),
        files,
        "nothing embedded but the files"
    );
}

/// A game or manipulator set up like another (`like`) has that one's presets for every learner:
/// the sliding puzzle TileSwap's, the three-link arm the two-link Reacher's.
#[test]
fn a_game_or_manipulator_like_another_takes_its_presets_for_every_learner() {
    for algorithm in learner_names() {
        for (env, like) in [
            ("sliding-reacher3", "tileswap-reacher"),
            ("sliding-cursor", "tileswap-cursor"),
            ("lightsout-reacher3", "lightsout-reacher"),
        ] {
            let mut config = TrainConfig::preset_for(env, algorithm).unwrap();
            config.env = like.into();
            assert_eq!(
                config,
                TrainConfig::preset_for(like, algorithm).unwrap(),
                "{algorithm} on {env}"
            );
        }
    }
    // A layer of one environment goes over its manipulator's: HAC on TileSwapCursor has the
    // seed's (tau_RB, alpha_low) of 0.5 (SPEC §5.2), on LightsOutCursor 0.1.
    for (env, value) in [("tileswap-cursor", 0.5), ("lightsout-cursor", 0.1)] {
        let hac = TrainConfig::preset_for(env, "hac").unwrap();
        let section: seads_run::HacConfig = hac.section().unwrap();
        assert_eq!(
            (section.temperature, hac.sac.alpha),
            (value, value),
            "{env}"
        );
    }
    // No layer of an unknown environment's manipulator makes a preset of it.
    assert!(TrainConfig::preset("nowhere-cursor").is_err());
    assert!(TrainConfig::preset("cursor").is_err());
}
