//! The flat layout of configuration files written before the algorithms had sections, and its
//! upgrade to the sectioned layout, so that every committed run's `config.toml` still loads.
//!
//! In the flat layout SEADS's settings (`num_skills`, the episode buffers, `eval_seeds`,
//! `[skill_model]`, `[reward]`, `[relabel]`) stood at the top, and both baselines shared a
//! `[baseline]` section beside `[hac]`. A baseline's file also held SEADS's settings at their
//! defaults.

use crate::RunError;
use crate::sections::Algorithm;

/// Keys of the top level that are SEADS's in the flat layout; the sectioned layout keeps them
/// in `[seads]`.
const SEADS_KEYS: [&str; 9] = [
    "num_skills",
    "episodes_per_epoch",
    "buffer_capacity",
    "recent_episodes",
    "sampled_episodes",
    "eval_seeds",
    "skill_model",
    "reward",
    "relabel",
];

/// The flat layout's section of both baselines.
const BASELINE: &str = "baseline";

/// Whether `table` has any key of the flat layout.
pub fn is_flat(table: &toml::Table) -> bool {
    table.contains_key(BASELINE) || SEADS_KEYS.iter().any(|k| table.contains_key(*k))
}

/// Moves the flat layout's keys of `table` (a configuration, or overrides of one, of
/// `algorithm`) into their sections: SEADS's into `[seads]`, `[baseline]` into `[sac_baseline]`
/// or `[hac]`. Returns whether the table was flat. A key given in both layouts is an error.
pub fn upgrade(table: &mut toml::Table, algorithm: Algorithm) -> Result<bool, RunError> {
    if !is_flat(table) {
        return Ok(false);
    }
    let mut seads = toml::Table::new();
    for key in SEADS_KEYS {
        if let Some(value) = table.remove(key) {
            seads.insert(key.into(), value);
        }
    }
    move_into(table, "seads", seads)?;
    if let Some(value) = table.remove(BASELINE) {
        let toml::Value::Table(baseline) = value else {
            return Err(RunError::Config("baseline must be a table".into()));
        };
        let section = match algorithm {
            Algorithm::Hac => "hac",
            Algorithm::Seads | Algorithm::Sac => "sac_baseline",
        };
        move_into(table, section, baseline)?;
    }
    Ok(true)
}

/// Adds `keys` to the section `name` of `table`.
fn move_into(table: &mut toml::Table, name: &str, keys: toml::Table) -> Result<(), RunError> {
    if keys.is_empty() {
        return Ok(());
    }
    let entry = table
        .entry(name)
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(section) = entry else {
        return Err(RunError::Config(format!("{name} must be a table")));
    };
    for (key, value) in keys {
        if section.contains_key(&key) {
            return Err(RunError::Config(format!(
                "{key} is given twice: at the top (the older, flat layout) and in [{name}]; \
                 keep the one in [{name}]"
            )));
        }
        section.insert(key, value);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn flat_keys_move_into_their_sections() {
        let mut t = table("env = \"x\"\nnum_skills = 30\n[relabel]\nsac_p = 0.0\n[sac]\nlr = 1.0");
        assert!(upgrade(&mut t, Algorithm::Seads).unwrap());
        assert_eq!(
            t,
            table(
                "env = \"x\"\n[sac]\nlr = 1.0\n[seads]\nnum_skills = 30\n[seads.relabel]\nsac_p = 0.0"
            )
        );
        let mut hac = table("[baseline]\neval_boards = 3\n[hac]\ntemperature = 0.5");
        assert!(upgrade(&mut hac, Algorithm::Hac).unwrap());
        assert_eq!(hac, table("[hac]\ntemperature = 0.5\neval_boards = 3"));
        let mut sac = table("[baseline]\neval_boards = 3");
        assert!(upgrade(&mut sac, Algorithm::Sac).unwrap());
        assert_eq!(sac, table("[sac_baseline]\neval_boards = 3"));
    }

    #[test]
    fn a_sectioned_table_is_left_alone_and_a_key_given_twice_is_refused() {
        let text = "env = \"x\"\n[seads]\nnum_skills = 30";
        let mut t = table(text);
        assert!(!upgrade(&mut t, Algorithm::Seads).unwrap());
        assert_eq!(t, table(text));
        let mut twice = table("num_skills = 30\n[seads]\nnum_skills = 15");
        let err = upgrade(&mut twice, Algorithm::Seads).unwrap_err();
        assert!(err.to_string().contains("given twice"), "{err}");
        let mut not_a_table = table("baseline = 3");
        assert!(upgrade(&mut not_a_table, Algorithm::Sac).is_err());
    }
}
