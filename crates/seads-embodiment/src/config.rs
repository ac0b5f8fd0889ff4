//! Configuration of an environment: board variant and reset distribution (SPEC §1.5, §1.6), and
//! the manipulator's own options.

use seads_games::Split;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::EnvError;

/// Options of an environment. `Default` gives the paper's training environment.
///
/// The board and reset options are shared by every environment; `manipulator` holds the
/// manipulator's own options (`[env_config.manipulator]` in a run's `config.toml`), which the
/// manipulator's options type reads when the environment is built
/// ([`EnvConfig::manipulator_options`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvConfig {
    /// Board side length; only `lightsout-cursor` accepts sizes other than the game's default
    /// (odd, 5 to 13, as spaced boards).
    pub board_size: Option<usize>,
    /// Relative spacing s ∈ [0, 1] between the fields of a spaced LightsOut board (fields keep
    /// side 1/13). Unset: 5×5 fields tile the board; larger boards use s = 0.
    pub spacing: Option<f64>,
    /// The split boards are drawn from at reset ("train" for training, "test" for evaluation).
    pub reset_split: Split,
    /// Largest solution depth of a reset board.
    pub max_solution_depth: usize,
    /// Draw the depth uniformly from 1..=max (training); otherwise use exactly the maximum.
    pub random_solution_depth: bool,
    /// Steps per skill, overriding the environment's default T_max.
    pub step_limit: Option<usize>,
    /// The manipulator's own options, by name (empty: its defaults). Which keys exist is the
    /// manipulator's business: the Cursor and the Reachers have none, the Jaco has
    /// `physics_substeps` ([`crate::JacoOptions`]).
    #[serde(skip_serializing_if = "serde_json::Map::is_empty")]
    pub manipulator: serde_json::Map<String, serde_json::Value>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            board_size: None,
            spacing: None,
            reset_split: Split::Train,
            max_solution_depth: 5,
            random_solution_depth: true,
            step_limit: None,
            manipulator: serde_json::Map::new(),
        }
    }
}

impl EnvConfig {
    /// Checks the values that do not depend on the environment.
    pub fn validate(&self) -> Result<(), EnvError> {
        let bad = |m: String| Err(EnvError::InvalidConfig(m));
        if self.max_solution_depth == 0 {
            return bad("max_solution_depth must be at least 1".into());
        }
        if let Some(s) = self.spacing
            && !(0.0..=1.0).contains(&s)
        {
            return bad(format!("spacing must lie in [0, 1], got {s}"));
        }
        if self.step_limit == Some(0) {
            return bad("step_limit must be at least 1".into());
        }
        Ok(())
    }

    /// The manipulator's options as its options type `T` (unset keys take `T`'s defaults); a
    /// key `T` does not have, or a value of the wrong type, is an error naming `env`.
    ///
    /// ```
    /// use seads_embodiment::{EnvConfig, EnvError, NoOptions};
    /// // A manipulator's options type: its keys, their defaults, unknown keys refused.
    /// #[derive(serde::Deserialize)]
    /// #[serde(deny_unknown_fields, default)]
    /// struct ArmOptions {
    ///     substeps: std::num::NonZeroUsize,
    /// }
    /// impl Default for ArmOptions {
    ///     fn default() -> Self {
    ///         Self { substeps: std::num::NonZeroUsize::MIN }
    ///     }
    /// }
    /// let mut config = EnvConfig::default();
    /// assert_eq!(config.manipulator_options::<ArmOptions>("my-arm")?.substeps.get(), 1);
    /// config.manipulator.insert("substeps".into(), 25.into());
    /// assert_eq!(config.manipulator_options::<ArmOptions>("my-arm")?.substeps.get(), 25);
    /// // A manipulator without options refuses the key; so does a zero here.
    /// assert!(config.manipulator_options::<NoOptions>("lightsout-cursor").is_err());
    /// config.manipulator.insert("substeps".into(), 0.into());
    /// assert!(config.manipulator_options::<ArmOptions>("my-arm").is_err());
    /// # Ok::<(), EnvError>(())
    /// ```
    pub fn manipulator_options<T: DeserializeOwned>(&self, env: &str) -> Result<T, EnvError> {
        serde_json::from_value(serde_json::Value::Object(self.manipulator.clone())).map_err(
            |source| EnvError::ManipulatorOptions {
                env: env.to_owned(),
                source,
            },
        )
    }
}

/// The options of a manipulator that has none: any key is refused.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoOptions {}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<EnvConfig, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn manipulator_options_round_trip_and_write_nothing_when_empty() {
        let config = parse("max_solution_depth = 3\n[manipulator]\nphysics_substeps = 25").unwrap();
        assert_eq!(config.manipulator["physics_substeps"], 25);
        let written = toml::to_string(&config).unwrap();
        assert!(
            written.contains("[manipulator]\nphysics_substeps = 25"),
            "{written}"
        );
        assert_eq!(parse(&written).unwrap(), config);
        let plain = toml::to_string(&EnvConfig::default()).unwrap();
        assert!(!plain.contains("manipulator"), "{plain}");
        assert_eq!(parse(&plain).unwrap(), EnvConfig::default());
    }

    #[test]
    fn a_manipulators_option_beside_the_board_options_is_an_unknown_field() {
        let err = parse("physics_substeps = 25").unwrap_err().to_string();
        assert!(err.contains("unknown field `physics_substeps`"), "{err}");
        assert!(err.contains("`manipulator`"), "{err}");
    }

    #[test]
    fn an_unknown_keys_error_lists_every_key_written() {
        let mut full = EnvConfig {
            board_size: Some(7),
            spacing: Some(0.5),
            step_limit: Some(10),
            ..EnvConfig::default()
        };
        full.manipulator
            .insert("physics_substeps".into(), 25.into());
        let written: toml::Table = toml::from_str(&toml::to_string(&full).unwrap()).unwrap();
        let mut keys: Vec<&str> = written.keys().map(String::as_str).collect();
        keys.sort_unstable();
        let mut listed = vec![
            "board_size",
            "spacing",
            "reset_split",
            "max_solution_depth",
            "random_solution_depth",
            "step_limit",
            "manipulator",
        ];
        listed.sort_unstable();
        assert_eq!(keys, listed);
    }

    #[test]
    fn no_options_refuses_every_key() {
        let mut config = EnvConfig::default();
        assert!(config.manipulator_options::<NoOptions>("x").is_ok());
        config.manipulator.insert("speed".into(), 1.into());
        let err = config.manipulator_options::<NoOptions>("x").unwrap_err();
        assert!(
            err.to_string()
                .starts_with("x: invalid manipulator options"),
            "{err}"
        );
        assert!(std::error::Error::source(&err).is_some());
    }
}
