//! Environments by name (SPEC §2.5): `make_env("lightsout-cursor", &config)`.

use seads_games::GameKind;
use serde::Serialize;

use crate::board::BoardState;
use crate::{Cursor, Embodied, EnvConfig, EnvError, Environment, Layout, Manipulator, Reacher};
#[cfg(feature = "jaco")]
use crate::{Jaco, JacoBoard};

/// One registered environment.
struct Entry {
    name: &'static str,
    description: &'static str,
    game: GameKind,
    embodiment: Embodiment,
}

#[derive(Clone, Copy)]
enum Embodiment {
    Cursor,
    Reacher,
    #[cfg(feature = "jaco")]
    Jaco(JacoBoard),
}

const REGISTRY: &[Entry] = &[
    Entry {
        name: "lightsout-cursor",
        description: "LightsOut 5×5 (or spaced 7×7…13×13) pushed by a 2-D cursor",
        game: GameKind::LightsOut,
        embodiment: Embodiment::Cursor,
    },
    Entry {
        name: "tileswap-cursor",
        description: "TileSwap 3×3 pushed by a 2-D cursor",
        game: GameKind::TileSwap,
        embodiment: Embodiment::Cursor,
    },
    Entry {
        name: "lightsout-reacher",
        description: "LightsOut 5×5 under a planar 2-link Reacher arm (exact MuJoCo dynamics)",
        game: GameKind::LightsOut,
        embodiment: Embodiment::Reacher,
    },
    Entry {
        name: "tileswap-reacher",
        description: "TileSwap 3×3 under a planar 2-link Reacher arm (exact MuJoCo dynamics)",
        game: GameKind::TileSwap,
        embodiment: Embodiment::Reacher,
    },
    #[cfg(feature = "jaco")]
    Entry {
        name: "lightsout-jaco",
        description: "LightsOut 5×5 pressed by a Kinova Jaco arm with 3-finger hand (rapier3d)",
        game: GameKind::LightsOut,
        embodiment: Embodiment::Jaco(JacoBoard::LightsOut { stairs: false }),
    },
    #[cfg(feature = "jaco")]
    Entry {
        name: "tileswap-jaco",
        description: "TileSwap 3×3 pressed by a Kinova Jaco arm with 3-finger hand (rapier3d)",
        game: GameKind::TileSwap,
        embodiment: Embodiment::Jaco(JacoBoard::TileSwap),
    },
    #[cfg(feature = "jaco")]
    Entry {
        name: "lightsout3d-jaco",
        description: "LightsOut 5×5 with fields raised by distance from the centre, pressed by a Jaco arm",
        game: GameKind::LightsOut,
        embodiment: Embodiment::Jaco(JacoBoard::LightsOut { stairs: true }),
    },
];

/// The registered environment names.
pub fn env_names() -> Vec<&'static str> {
    REGISTRY.iter().map(|e| e.name).collect()
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
    let entry = REGISTRY
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| EnvError::UnknownEnv {
            name: name.to_owned(),
            valid: env_names().join(", "),
        })?;
    config.validate()?;
    let layout = layout(entry, config)?;
    #[cfg(feature = "jaco")]
    let jaco = matches!(entry.embodiment, Embodiment::Jaco(_));
    #[cfg(not(feature = "jaco"))]
    let jaco = false;
    if config.physics_substeps.is_some() && !jaco {
        return Err(EnvError::InvalidConfig(format!(
            "physics_substeps applies to the Jaco environments, not {}",
            entry.name
        )));
    }
    let size = match layout {
        Layout::Grid { n } | Layout::Spaced { n, .. } | Layout::ColumnMajor { n } => n,
        Layout::Pivots => 3,
    };
    let board = BoardState::new(entry.game, size, config)?;
    Ok(match entry.embodiment {
        Embodiment::Cursor => build(entry.name, Cursor::default(), board, layout, config),
        Embodiment::Reacher => build(entry.name, Reacher::default(), board, layout, config),
        #[cfg(feature = "jaco")]
        Embodiment::Jaco(jaco) => {
            let substeps = config
                .physics_substeps
                .unwrap_or(crate::jaco::DEFAULT_SUBSTEPS);
            build(entry.name, Jaco::new(jaco, substeps), board, layout, config)
        }
    })
}

fn build<M: Manipulator>(
    name: &str,
    manipulator: M,
    board: BoardState,
    layout: Layout,
    config: &EnvConfig,
) -> Box<dyn Environment> {
    Box::new(Embodied::new(
        name,
        manipulator,
        board,
        layout,
        config.step_limit,
    ))
}

/// The board layout an entry gets under `config`; only `lightsout-cursor` has variants.
fn layout(entry: &Entry, config: &EnvConfig) -> Result<Layout, EnvError> {
    let default = entry.game.default_size();
    let size = config.board_size.unwrap_or(default);
    let variant = size != default || config.spacing.is_some();
    if !variant {
        // The reference numbers LightsOut3DJaco's fields column by column.
        #[cfg(feature = "jaco")]
        if matches!(
            entry.embodiment,
            Embodiment::Jaco(JacoBoard::LightsOut { stairs: true })
        ) {
            return Ok(Layout::ColumnMajor { n: size });
        }
        return Ok(Layout::standard(entry.game, size));
    }
    if entry.name != "lightsout-cursor" {
        return Err(EnvError::InvalidConfig(format!(
            "{} has only the {default}×{default} board; board_size and spacing apply to lightsout-cursor",
            entry.name
        )));
    }
    if !(5..=13).contains(&size) || size.is_multiple_of(2) {
        return Err(EnvError::InvalidConfig(format!(
            "spaced LightsOut boards have odd sizes 5 to 13, got {size}"
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
    REGISTRY
        .iter()
        .map(|e| {
            let env =
                make_env(e.name, &EnvConfig::default()).expect("registered environments build");
            let spec = env.spec();
            EnvInfo {
                name: e.name.to_owned(),
                description: e.description.to_owned(),
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
