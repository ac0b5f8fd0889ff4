//! Which runs can train together in one population (`seads-rl`'s `Population`): those whose
//! networks and environments have the same shapes. Sweeps group their runs by it.

use crate::{RunError, TrainConfig};

/// What members of one population must share: everything that fixes the shapes of their
/// networks and environments, and what is set per process (kernels, device). Settings such as
/// seeds, learning rates or relabelling may differ.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PopulationKey(String);

impl PopulationKey {
    /// The key of a run with `config`.
    pub fn of(config: &TrainConfig) -> Self {
        let values: Vec<String> = Self::fields(config).into_iter().map(|(_, v)| v).collect();
        Self(values.join("|"))
    }

    /// Why `a` and `b` cannot share a population (the first field that differs), if they cannot.
    pub fn mismatch(a: &TrainConfig, b: &TrainConfig) -> Option<String> {
        Self::fields(a)
            .into_iter()
            .zip(Self::fields(b))
            .find(|((_, x), (_, y))| x != y)
            .map(|((field, x), (_, y))| format!("{field} differs ({x} against {y})"))
    }

    /// The settings members must share, named as in `config.toml`, in words.
    fn fields(c: &TrainConfig) -> [(&'static str, String); 8] {
        let env_config = serde_json::to_string(&c.env_config).unwrap_or_default();
        [
            ("algorithm", c.algorithm().to_owned()),
            ("env", c.env.clone()),
            ("env_config", env_config),
            (
                "num_skills",
                c.seads()
                    .map_or(String::new(), |s| format!("{:?}", s.num_skills)),
            ),
            ("sac.hidden", format!("{:?}", c.sac.hidden)),
            (
                "skill_model",
                c.seads().map_or(String::new(), |s| {
                    format!("{:?} {:?}", s.skill_model.kind, s.skill_model.hidden)
                }),
            ),
            ("portable_numerics", c.portable_numerics.to_string()),
            ("device", c.device.to_string()),
        ]
    }
}

/// Checks that runs with `configs` can train as one population: at least one member, and every
/// member's [`PopulationKey`] equal to the first's. The error names the first member that differs
/// and the field.
pub fn check_population(configs: &[(String, TrainConfig)]) -> Result<(), RunError> {
    let Some((first_name, first)) = configs.first() else {
        return Err(RunError::Config(
            "a population needs at least one run".into(),
        ));
    };
    for (name, config) in &configs[1..] {
        if let Some(why) = PopulationKey::mismatch(first, config) {
            return Err(RunError::Config(format!(
                "{name} cannot train in one population with {first_name}: {why}"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_and_rates_share_a_key_shapes_and_environments_do_not() {
        let a = TrainConfig::preset("lightsout-cursor").unwrap();
        let mut b = a.clone();
        (b.seed, b.sac.lr) = (7, 1e-3);
        b.edit(|s: &mut crate::SeadsConfig| s.relabel.sac_p = 0.0)
            .unwrap();
        assert_eq!(PopulationKey::of(&a), PopulationKey::of(&b));
        assert_eq!(PopulationKey::mismatch(&a, &b), None);
        b.sac.hidden = vec![128, 128];
        assert_ne!(PopulationKey::of(&a), PopulationKey::of(&b));
        let why = PopulationKey::mismatch(&a, &b).unwrap();
        assert!(why.starts_with("sac.hidden differs"), "{why}");
        let c = TrainConfig::preset("tileswap-cursor").unwrap();
        assert!(
            PopulationKey::mismatch(&a, &c)
                .unwrap()
                .starts_with("env differs")
        );
        assert!(check_population(&[]).is_err());
    }
}
