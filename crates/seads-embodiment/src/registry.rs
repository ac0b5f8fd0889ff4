//! Environments by name (SPEC §2.5): `make_env("lightsout-cursor", &config)`.
//!
//! An environment is a (game × manipulator) pair. The Cursor and the Reachers play every game of
//! the games' registry (`<game>-cursor`, `<game>-reacher`, `<game>-reacher3`), so a new game
//! needs no entry here;
//! the Jaco arm plays the games it has a physical board for.

use std::sync::OnceLock;

use seads_games::{BoardGame, GameKind, MoveSite};
use serde::Serialize;

use crate::board::BoardState;
use crate::{
    Cursor, Embodied, EnvConfig, EnvError, Environment, Layout, Manipulator, NoOptions, Reacher,
    Reacher3,
};
#[cfg(feature = "jaco")]
use crate::{Jaco, JacoBoard};

/// One registered environment.
struct Entry {
    name: String,
    /// CamelCase name (`LightsOutCursor`), for Gymnasium ids.
    title: String,
    description: String,
    game: GameKind,
    embodiment: Embodiment,
}

#[derive(Clone, Copy, PartialEq)]
enum Embodiment {
    Cursor,
    Reacher,
    Reacher3,
    #[cfg(feature = "jaco")]
    Jaco(JacoBoard),
}

/// The manipulators that play every game: name, title and how they push.
const EVERY_GAME: [(Embodiment, &str, &str, &str); 3] = [
    (
        Embodiment::Cursor,
        "cursor",
        "Cursor",
        "pushed by a 2-D cursor",
    ),
    (
        Embodiment::Reacher,
        "reacher",
        "Reacher",
        "under a planar 2-link Reacher arm (exact MuJoCo dynamics)",
    ),
    (
        Embodiment::Reacher3,
        "reacher3",
        "Reacher3",
        "under a planar 3-link Reacher arm (MuJoCo's dynamics)",
    ),
];

/// Every environment: the Cursor and the two Reachers on each game, then the Jaco boards.
fn registry() -> &'static [Entry] {
    static REGISTRY: OnceLock<Vec<Entry>> = OnceLock::new();
    REGISTRY.get_or_init(|| {
        let mut entries = Vec::new();
        for (embodiment, arm, arm_title, how) in EVERY_GAME {
            for game in GameKind::all() {
                let n = game.default_size();
                entries.push(Entry {
                    name: format!("{}-{arm}", game.name()),
                    title: format!("{}{arm_title}", game.title()),
                    description: format!("{} {n}×{n} {how}", game.title()),
                    game,
                    embodiment,
                });
            }
        }
        #[cfg(feature = "jaco")]
        entries.extend(jaco_entries());
        entries
    })
}

/// The Jaco arm's boards: LightsOut flat and raised as stairs, and TileSwap.
#[cfg(feature = "jaco")]
fn jaco_entries() -> Vec<Entry> {
    let game = |name| GameKind::named(name).expect("a registered game");
    let entry = |name: &str, title: &str, description: &str, game, board| Entry {
        name: name.to_owned(),
        title: title.to_owned(),
        description: description.to_owned(),
        game,
        embodiment: Embodiment::Jaco(board),
    };
    vec![
        entry(
            "lightsout-jaco",
            "LightsOutJaco",
            "LightsOut 5×5 pressed by a Kinova Jaco arm with 3-finger hand (rapier3d)",
            game("lightsout"),
            JacoBoard::LightsOut { stairs: false },
        ),
        entry(
            "tileswap-jaco",
            "TileSwapJaco",
            "TileSwap 3×3 pressed by a Kinova Jaco arm with 3-finger hand (rapier3d)",
            game("tileswap"),
            JacoBoard::TileSwap,
        ),
        entry(
            "lightsout3d-jaco",
            "LightsOut3DJaco",
            "LightsOut 5×5 with fields raised by distance from the centre, pressed by a Jaco arm",
            game("lightsout"),
            JacoBoard::LightsOut { stairs: true },
        ),
    ]
}

/// The registered environment names.
pub fn env_names() -> Vec<&'static str> {
    registry().iter().map(|e| e.name.as_str()).collect()
}

/// Builds the environment `name` with `config` (validated).
///
/// ```
/// use seads_embodiment::{EnvConfig, make_env};
/// let mut env = make_env("lightsout-cursor", &EnvConfig::default())?;
/// env.seed(3);
/// env.reset()?;
/// // Observations are [manipulator, board bits, time left]; actions are checked first.
/// let spec = env.spec().clone();
/// assert_eq!(spec.obs_dim, spec.manipulator_dim + spec.symbolic_len + 1);
/// assert!(env.step(&[f32::NAN, 0.0, 0.0]).is_err());
/// let step = env.step(&vec![0.0; spec.action_dim])?;
/// assert!(!step.truncated, "one step of ten");
/// assert!(make_env("chess-robot", &EnvConfig::default()).is_err());
/// # Ok::<(), seads_embodiment::EnvError>(())
/// ```
pub fn make_env(name: &str, config: &EnvConfig) -> Result<Box<dyn Environment>, EnvError> {
    let entry = registry()
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| EnvError::UnknownEnv {
            name: name.to_owned(),
            valid: env_names().join(", "),
        })?;
    config.validate()?;
    let game = entry
        .game
        .build(config.board_size.unwrap_or(entry.game.default_size()))
        .map_err(|e| EnvError::InvalidConfig(format!("{}: {e}", entry.name)))?;
    let layout = layout(entry, game.as_ref(), config)?;
    let board = BoardState::new(entry.game, game.size(), config)?;
    let name = entry.name.as_str();
    match entry.embodiment {
        Embodiment::Cursor => {
            let NoOptions {} = config.manipulator_options(name)?;
            build(name, Cursor::default(), board, layout, config)
        }
        Embodiment::Reacher => {
            let NoOptions {} = config.manipulator_options(name)?;
            build(name, Reacher::default(), board, layout, config)
        }
        Embodiment::Reacher3 => {
            let NoOptions {} = config.manipulator_options(name)?;
            build(name, Reacher3::default(), board, layout, config)
        }
        #[cfg(feature = "jaco")]
        Embodiment::Jaco(jaco) => {
            let options: crate::JacoOptions = config.manipulator_options(name)?;
            let substeps = options.physics_substeps.get();
            build(name, Jaco::new(jaco, substeps), board, layout, config)
        }
    }
}

fn build<M: Manipulator>(
    name: &str,
    manipulator: M,
    board: BoardState,
    layout: Layout,
    config: &EnvConfig,
) -> Result<Box<dyn Environment>, EnvError> {
    Ok(Box::new(Embodied::new(
        name,
        manipulator,
        board,
        layout,
        config.step_limit,
    )?))
}

/// The board layout an entry gets under `config`: fields tiling the board, or the pivots
/// between them where the game's moves are made at edges. Other sizes are for the Cursor, on
/// games whose moves are made at fields: up to 5×5 the fields tile the board, larger boards
/// and any `spacing` keep fields of side 1/13 (SPEC §1.6).
fn layout(entry: &Entry, game: &dyn BoardGame, config: &EnvConfig) -> Result<Layout, EnvError> {
    let default = entry.game.default_size();
    let size = game.size();
    let variant = size != default || config.spacing.is_some();
    let at_fields = matches!(game.move_site(0), MoveSite::Field(_));
    if !variant {
        // The reference numbers LightsOut3DJaco's fields column by column.
        #[cfg(feature = "jaco")]
        if matches!(
            entry.embodiment,
            Embodiment::Jaco(JacoBoard::LightsOut { stairs: true })
        ) {
            return Ok(Layout::ColumnMajor { n: size });
        }
        return Layout::standard(game)
            .ok_or_else(|| EnvError::InvalidConfig(format!("{} has no board layout", entry.name)));
    }
    if entry.embodiment != Embodiment::Cursor || !at_fields {
        return Err(EnvError::InvalidConfig(format!(
            "{} has only the {default}×{default} board; board_size and spacing apply to the Cursor on games pushed at fields",
            entry.name
        )));
    }
    // Boards up to 5×5 tile the square; larger ones keep fields of side 1/13 (SPEC §1.6).
    if size <= 5 && config.spacing.is_none() {
        return Ok(Layout::Grid { n: size });
    }
    if !(5..=13).contains(&size) || size.is_multiple_of(2) {
        return Err(EnvError::InvalidConfig(format!(
            "spaced boards have odd sizes 5 to 13, got {size}"
        )));
    }
    Ok(Layout::Spaced {
        n: size,
        spacing: config.spacing.unwrap_or(0.0),
    })
}

/// Summary of a registered environment, as listed by `seads envs`.
#[derive(Debug, Clone, Serialize)]
pub struct EnvInfo {
    /// Registered name.
    pub name: String,
    /// CamelCase name (`LightsOutCursor`), for Gymnasium ids.
    pub title: String,
    /// One line.
    pub description: String,
    /// Observation length.
    pub obs_dim: usize,
    /// Action length.
    pub action_dim: usize,
    /// Number of skills K.
    pub num_skills: usize,
    /// Steps per skill T_max.
    pub step_limit: usize,
}

/// Every registered environment with its default dimensions.
pub fn list_envs() -> Vec<EnvInfo> {
    registry()
        .iter()
        .map(|e| {
            let env =
                make_env(&e.name, &EnvConfig::default()).expect("registered environments build");
            let spec = env.spec();
            EnvInfo {
                name: e.name.clone(),
                title: e.title.clone(),
                description: e.description.clone(),
                obs_dim: spec.obs_dim,
                action_dim: spec.action_dim,
                num_skills: spec.num_skills,
                step_limit: spec
                    .step_limit
                    .expect("default environments have a step limit"),
            }
        })
        .collect()
}
