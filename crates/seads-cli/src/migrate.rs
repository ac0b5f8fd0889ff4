//! `seads migrate`: rewrites files of the older layouts into today's, once. The libraries read
//! today's layout only; this command is the one place that knows the older ones:
//! - a run's `config.toml` in the flat layout (SEADS's settings at the top, both baselines'
//!   in `[baseline]`, every algorithm's section written at its defaults), with the Jaco's
//!   `physics_substeps` beside the board options, or with SAC's `updates_per_epoch` in `[sac]`;
//! - a study's manifest whose overrides use those layouts;
//! - an evaluation file that is a bare list of per-depth results;
//! - a checkpoint's episode table whose symbolic states have three 64-bit words, not four.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use seads_rl::{BaselineConfig, HacConfig, SeadsConfig, Section, TrainConfig};

/// The learners the older layouts knew (they knew no others), and `Newer`: a learner added
/// since, whose files are in today's layout by birth (nothing of them is migrated).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum Algorithm {
    #[default]
    Seads,
    Sac,
    Hac,
    Newer,
}

impl Algorithm {
    const ALL: [Algorithm; 3] = [Algorithm::Seads, Algorithm::Sac, Algorithm::Hac];

    /// Its name in configurations.
    fn name(self) -> &'static str {
        match self {
            Algorithm::Seads => SeadsConfig::ALGORITHM,
            Algorithm::Sac => BaselineConfig::ALGORITHM,
            Algorithm::Hac => HacConfig::ALGORITHM,
            Algorithm::Newer => "a newer learner",
        }
    }

    /// Its section's name.
    fn section(self) -> &'static str {
        match self {
            Algorithm::Seads => SeadsConfig::NAME,
            Algorithm::Sac => BaselineConfig::NAME,
            Algorithm::Hac => HacConfig::NAME,
            Algorithm::Newer => "its own section",
        }
    }

    /// The learner of this name, if the older layouts knew it, or [`Algorithm::Newer`] for a
    /// learner with presets today.
    fn named(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|a| a.name() == name)
            .or_else(|| seads_rl::section_name(name).map(|_| Algorithm::Newer))
    }
}

use crate::BadInput;

/// `seads migrate`.
#[derive(Debug, Args)]
pub struct MigrateArgs {
    /// Files or folders (searched through) to rewrite: runs' `config.toml`, study manifests
    /// (`manifest.toml`, or any `.toml` with `[[variant]]`), evaluation files
    /// (`evaluation*.json`) and checkpoints' episode tables (`episodes.safetensors`). Other files
    /// are left alone.
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// Rewrite nothing: list the files in an older layout, and fail (exit 1) if there are any.
    #[arg(long)]
    pub check: bool,
}

/// The kinds of file migrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Config,
    Manifest,
    Evaluation,
    Episodes,
}

impl Kind {
    /// The kind of the file at `path`, by its name.
    fn of(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_str()?;
        if name == "config.toml" {
            Some(Self::Config)
        } else if name.ends_with(".toml") {
            Some(Self::Manifest)
        } else if name.starts_with("evaluation") && name.ends_with(".json") {
            Some(Self::Evaluation)
        } else if name == seads_rl::store::EPISODES_FILE {
            Some(Self::Episodes)
        } else {
            None
        }
    }

    /// Today's contents of the file at `path` of this kind, or `None` where it is already in
    /// today's layout (or is no file of this kind: a `.toml` that is no manifest, a
    /// `config.toml` without `env`).
    fn migrate(self, path: &Path) -> Result<Option<Vec<u8>>> {
        if self == Self::Episodes {
            return migrate_episodes(path);
        }
        let text = std::fs::read_to_string(path)?;
        let new = match self {
            Self::Config => migrate_config(&text),
            Self::Manifest => migrate_manifest(&text),
            Self::Evaluation | Self::Episodes => migrate_evaluation(&text),
        }?;
        Ok(new.map(String::into_bytes))
    }
}

/// `seads migrate`.
pub fn migrate(args: MigrateArgs) -> Result<()> {
    let mut files = Vec::new();
    for path in &args.paths {
        if !path.exists() {
            return Err(BadInput(anyhow!("{} does not exist", path.display())).into());
        }
        for entry in walkdir::WalkDir::new(path).sort_by_file_name() {
            let entry = entry.with_context(|| format!("reading {}", path.display()))?;
            if entry.file_type().is_file()
                && let Some(kind) = Kind::of(entry.path())
            {
                files.push((entry.into_path(), kind));
            }
        }
    }
    // Every file is read and migrated before any is written: a file that cannot be migrated
    // leaves all of them as they were. (Each is migrated again when it is written, so that no
    // more than one file's new contents is held at a time.)
    let mut changed = Vec::new();
    for (path, kind) in &files {
        if kind
            .migrate(path)
            .map_err(|e| BadInput(e.context(format!("migrating {}", path.display()))))?
            .is_some()
        {
            changed.push((path, *kind));
        }
    }
    let count = |kind| changed.iter().filter(|(_, k)| *k == kind).count();
    let summary = format!(
        "{} run configuration(s), {} manifest(s), {} evaluation file(s), {} episode table(s)",
        count(Kind::Config),
        count(Kind::Manifest),
        count(Kind::Evaluation),
        count(Kind::Episodes)
    );
    if args.check {
        for (path, _) in &changed {
            outln!("{}", path.display());
        }
        if changed.is_empty() {
            outln!("all {} file(s) are in today's layout", files.len());
            return Ok(());
        }
        bail!("in an older layout: {summary} (`seads migrate` rewrites them)");
    }
    for (path, kind) in &changed {
        if let Some(new) = kind.migrate(path)? {
            seads_rl::store::write_atomic(path, &new)
                .with_context(|| format!("writing {}", path.display()))?;
        }
    }
    outln!(
        "migrated {summary}; {} other file(s) were in today's layout",
        files.len() - changed.len()
    );
    Ok(())
}

/// SEADS's keys at the top of the flat layout; today's layout keeps them in `[seads]`.
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

/// SAC's gradient steps per epoch in the older layouts' `[sac]`, where a baseline had to keep
/// them at this default.
const SAC_UPDATES: i64 = 16;

/// Brings a configuration's table, or a layer of overrides, of `algorithm` into today's
/// layout: the flat layout's keys into their sections, the Jaco's `physics_substeps` into
/// `[env_config.manipulator]`, SAC's `updates_per_epoch` into `[seads]`.
fn upgrade(table: &mut toml::Table, algorithm: Algorithm) -> Result<()> {
    if algorithm == Algorithm::Newer {
        return Ok(());
    }
    let mut seads = toml::Table::new();
    for key in SEADS_KEYS {
        if let Some(value) = table.remove(key) {
            seads.insert(key.into(), value);
        }
    }
    move_into(table, "seads", seads)?;
    if let Some(value) = table.remove("baseline") {
        let toml::Value::Table(baseline) = value else {
            bail!("baseline must be a table");
        };
        // (A newer learner returned above: nothing of it is migrated.)
        let section = match algorithm {
            Algorithm::Hac => "hac",
            Algorithm::Seads | Algorithm::Sac | Algorithm::Newer => "sac_baseline",
        };
        move_into(table, section, baseline)?;
    }
    if let Some(toml::Value::Table(env_config)) = table.get_mut("env_config")
        && let Some(value) = env_config.remove("physics_substeps")
    {
        let mut moved = toml::Table::new();
        moved.insert("physics_substeps".into(), value);
        move_into(env_config, "manipulator", moved)?;
    }
    let updates = match table.get_mut("sac") {
        Some(toml::Value::Table(sac)) => sac.remove("updates_per_epoch"),
        _ => None,
    };
    if let Some(updates) = updates {
        if matches!(table.get("sac"), Some(toml::Value::Table(sac)) if sac.is_empty()) {
            table.remove("sac");
        }
        if algorithm == Algorithm::Seads {
            let mut moved = toml::Table::new();
            moved.insert("updates_per_epoch".into(), updates);
            move_into(table, "seads", moved)?;
        } else if updates.as_integer() != Some(SAC_UPDATES) {
            bail!(
                "sac.updates_per_epoch = {updates} in a {} configuration, which older versions \
                 refused too: the baseline's own is {}.updates_per_epoch",
                algorithm.name(),
                algorithm.section()
            );
        }
    }
    Ok(())
}

/// Adds `keys` to the table `name` of `table`; a key there already is an error.
fn move_into(table: &mut toml::Table, name: &str, keys: toml::Table) -> Result<()> {
    if keys.is_empty() {
        return Ok(());
    }
    let entry = table
        .entry(name)
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(section) = entry else {
        bail!("{name} must be a table");
    };
    for (key, value) in keys {
        if section.contains_key(&key) {
            bail!("{key} is given twice: in the older layout and in today's `{name}`");
        }
        section.insert(key, value);
    }
    Ok(())
}

/// The algorithm a table names (`None` where it names none).
fn named_algorithm(table: &toml::Table) -> Result<Option<Algorithm>> {
    table
        .get("algorithm")
        .map(|value| {
            value
                .as_str()
                .and_then(Algorithm::named)
                .ok_or_else(|| anyhow!("unknown algorithm {value}"))
        })
        .transpose()
}

/// Removes the sections of the algorithms other than `algorithm` from a whole configuration,
/// where the older layout wrote them at their defaults; one that holds anything else is an
/// error, as it was then.
fn drop_default_sections(table: &mut toml::Table, algorithm: Algorithm) -> Result<()> {
    fn at_default<T: serde::de::DeserializeOwned + Default + PartialEq>(
        value: toml::Value,
    ) -> Result<bool> {
        Ok(value.try_into::<T>()? == T::default())
    }
    if algorithm == Algorithm::Newer {
        return Ok(());
    }
    for other in Algorithm::ALL.into_iter().filter(|&a| a != algorithm) {
        let Some(value) = table.remove(other.section()) else {
            continue;
        };
        let default = match other {
            Algorithm::Seads => at_default::<SeadsConfig>(value)?,
            Algorithm::Sac => at_default::<BaselineConfig>(value)?,
            Algorithm::Hac => at_default::<HacConfig>(value)?,
            Algorithm::Newer => true,
        };
        if !default {
            bail!(
                "[{}] of algorithm {:?} in a {:?} configuration holds other values than its \
                 defaults",
                other.section(),
                other.name(),
                algorithm.name()
            );
        }
    }
    Ok(())
}

/// A run's `config.toml` in today's layout, as today's binary writes it (comments are not kept:
/// runs write none).
fn migrate_config(text: &str) -> Result<Option<String>> {
    let mut table: toml::Table = text.parse()?;
    if !table.contains_key("env") {
        return Ok(None);
    }
    let algorithm = named_algorithm(&table)?.unwrap_or_default();
    upgrade(&mut table, algorithm)?;
    drop_default_sections(&mut table, algorithm)?;
    let new = TrainConfig::from_table(table)?.to_toml();
    // A file that states today's values in today's layout stays as written (with its comments).
    let same = text.parse::<toml::Table>()? == new.parse::<toml::Table>()?;
    Ok((!same).then_some(new))
}

/// A study's manifest with its overrides in today's layout, comments and order kept.
fn migrate_manifest(text: &str) -> Result<Option<String>> {
    let mut doc: toml_edit::DocumentMut = text.parse()?;
    let Some(mut variants) = doc
        .get_mut("variant")
        .and_then(|v| v.as_array_of_tables_mut())
        .map(std::mem::take)
    else {
        return Ok(None);
    };
    // The algorithm of a variant: the last layer that names one (as planning reads it).
    let study = doc_layer_algorithm(doc.get("overrides"))?;
    if let Some(item) = doc.get_mut("overrides") {
        upgrade_item(item, study.unwrap_or_default())?;
    }
    for variant in variants.iter_mut() {
        let own = doc_layer_algorithm(variant.get("overrides"))?.or(study);
        if let Some(item) = variant.get_mut("overrides") {
            upgrade_item(item, own.unwrap_or_default())?;
        }
        if let Some(envs) = variant.get_mut("env_overrides") {
            let mut table = item_table(envs)?;
            let mut changed = false;
            for (_, layer) in table.iter_mut() {
                let toml::Value::Table(layer) = layer else {
                    bail!("env_overrides must map environments to tables");
                };
                let algorithm = named_algorithm(layer)?.or(own).unwrap_or_default();
                let before = layer.clone();
                upgrade(layer, algorithm)?;
                changed |= *layer != before;
            }
            if changed {
                replace_item(envs, &table)?;
            }
        }
    }
    doc["variant"] = toml_edit::Item::ArrayOfTables(variants);
    let new = doc.to_string();
    Ok((new != text).then_some(new))
}

/// The algorithm a layer of overrides names.
fn doc_layer_algorithm(item: Option<&toml_edit::Item>) -> Result<Option<Algorithm>> {
    match item {
        Some(item) => named_algorithm(&item_table(item)?),
        None => Ok(None),
    }
}

/// A manifest's table (inline or not) as a plain TOML table.
fn item_table(item: &toml_edit::Item) -> Result<toml::Table> {
    let value = item
        .clone()
        .into_value()
        .map_err(|_| anyhow!("overrides must be tables"))?;
    let mut wrapped: toml::Table = format!("layer = {value}").parse()?;
    match wrapped.remove("layer") {
        Some(toml::Value::Table(table)) => Ok(table),
        _ => bail!("overrides must be tables"),
    }
}

/// Replaces a manifest's table with `table`, inline where it was inline.
fn replace_item(item: &mut toml_edit::Item, table: &toml::Table) -> Result<()> {
    let text = toml::Value::Table(sorted(table)).to_string();
    let value: toml_edit::Value = text.parse()?;
    match item {
        toml_edit::Item::Value(old) => {
            let decor = old.decor().clone();
            *old = value;
            *old.decor_mut() = decor;
        }
        other => {
            let toml_edit::Value::InlineTable(inline) = value else {
                bail!("overrides must be tables");
            };
            *other = toml_edit::Item::Table(inline.into_table());
        }
    }
    Ok(())
}

/// `table` with its keys in order, at every depth: how the migrated manifests were written.
fn sorted(table: &toml::Table) -> toml::Table {
    let mut keys: Vec<&String> = table.keys().collect();
    keys.sort();
    keys.into_iter()
        .map(|key| {
            let value = match &table[key] {
                toml::Value::Table(inner) => toml::Value::Table(sorted(inner)),
                other => other.clone(),
            };
            (key.clone(), value)
        })
        .collect()
}

/// Upgrades one manifest layer of `algorithm`, rewriting it only where it changes.
fn upgrade_item(item: &mut toml_edit::Item, algorithm: Algorithm) -> Result<()> {
    let before = item_table(item)?;
    let mut table = before.clone();
    upgrade(&mut table, algorithm)?;
    if table != before {
        replace_item(item, &table)?;
    }
    Ok(())
}

/// An evaluation file as a record: a bare list of per-depth results becomes a record that
/// names no checkpoint and no protocol (it recorded neither).
fn migrate_evaluation(text: &str) -> Result<Option<String>> {
    let value: serde_json::Value = serde_json::from_str(text)?;
    let serde_json::Value::Array(results) = value else {
        return Ok(None);
    };
    let record = serde_json::json!({ "checkpoint": null, "protocol": null, "results": results });
    let record = seads_planner::EvaluationRecord::from_json(&record.to_string())?;
    Ok(Some(record.to_json()))
}

/// A checkpoint's episode table with four 64-bit words a symbolic state: a table of three
/// (states before they grew to 256 bits) gets a fourth word of zeros.
fn migrate_episodes(path: &Path) -> Result<Option<Vec<u8>>> {
    const WORDS: i64 = seads_games::SymbolicState::WORDS as i64;
    let tensors = tch::Tensor::read_safetensors(path)?;
    let width = |name: &str| {
        tensors
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.size())
            .and_then(|size| (size.len() == 2).then(|| size[1]))
            .ok_or_else(|| anyhow!("no table {name} of symbolic states"))
    };
    match (width("z0")?, width("zt")?) {
        (WORDS, WORDS) => return Ok(None),
        (3, 3) => {}
        (a, b) => bail!("symbolic states of {a} and {b} words, neither 3 nor {WORDS}"),
    }
    let widened: Vec<(String, tch::Tensor)> = tensors
        .into_iter()
        .map(|(name, t)| {
            let t = if name == "z0" || name == "zt" {
                let zeros = tch::Tensor::zeros([t.size()[0], WORDS - 3], (t.kind(), t.device()));
                tch::Tensor::cat(&[t, zeros], 1)
            } else {
                t
            };
            (name, t)
        })
        .collect();
    let scratch = tempfile::NamedTempFile::new_in(path.parent().unwrap_or(Path::new(".")))?;
    tch::Tensor::write_safetensors(&widened, scratch.path())?;
    Ok(Some(std::fs::read(scratch.path())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A learner added since the older layouts (DIAYN) is in today's layout by birth: its
    /// configurations and manifest layers are left as they are; a name no learner has is an
    /// error.
    #[test]
    fn a_newer_learners_files_are_left_alone() {
        let config = seads_rl::TrainConfig::preset_for("lightsout-cursor", "diayn")
            .unwrap()
            .to_toml();
        assert_eq!(migrate_config(&config).unwrap(), None);
        let manifest = "name = \"m\"\nenvironments = [\"lightsout-cursor\"]\nseeds = [1]\n\
                        [[variant]]\nname = \"diayn\"\noverrides = { algorithm = \"diayn\" }\n";
        assert_eq!(migrate_manifest(manifest).unwrap(), None);
        let unknown = manifest.replace("algorithm = \"diayn\"", "algorithm = \"ppo\"");
        let err = migrate_manifest(&unknown).unwrap_err().to_string();
        assert!(err.contains("unknown algorithm \"ppo\""), "{err}");
    }

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn flat_keys_move_into_their_sections() {
        let mut t = table("env = \"x\"\nnum_skills = 30\n[relabel]\nsac_p = 0.0\n[sac]\nlr = 1.0");
        upgrade(&mut t, Algorithm::Seads).unwrap();
        assert_eq!(
            t,
            table(
                "env = \"x\"\n[sac]\nlr = 1.0\n[seads]\nnum_skills = 30\n[seads.relabel]\nsac_p = 0.0"
            )
        );
        let mut hac = table("[baseline]\neval_boards = 3\n[hac]\ntemperature = 0.5");
        upgrade(&mut hac, Algorithm::Hac).unwrap();
        assert_eq!(hac, table("[hac]\ntemperature = 0.5\neval_boards = 3"));
        let mut sac = table("[baseline]\neval_boards = 3");
        upgrade(&mut sac, Algorithm::Sac).unwrap();
        assert_eq!(sac, table("[sac_baseline]\neval_boards = 3"));
        let mut twice = table("num_skills = 30\n[seads]\nnum_skills = 15");
        let err = upgrade(&mut twice, Algorithm::Seads).unwrap_err();
        assert!(err.to_string().contains("given twice"), "{err}");
    }

    #[test]
    fn substeps_and_sac_updates_move_to_their_sections() {
        let mut t = table(
            "[env_config]\nphysics_substeps = 25\n[sac]\nupdates_per_epoch = 8\n[seads]\neval_seeds = 2",
        );
        upgrade(&mut t, Algorithm::Seads).unwrap();
        assert_eq!(
            t,
            table(
                "[env_config.manipulator]\nphysics_substeps = 25\n[seads]\neval_seeds = 2\nupdates_per_epoch = 8"
            )
        );
        // A baseline kept SEADS's default there, which goes.
        let mut sac = table("algorithm = \"sac\"\n[sac]\nlr = 1.0\nupdates_per_epoch = 16");
        upgrade(&mut sac, Algorithm::Sac).unwrap();
        assert_eq!(sac, table("algorithm = \"sac\"\n[sac]\nlr = 1.0"));
        let mut odd = table("[sac]\nupdates_per_epoch = 4");
        assert!(upgrade(&mut odd, Algorithm::Hac).is_err());
    }

    /// A flat SAC baseline's file as the older binaries wrote it (every section, SEADS's at its
    /// defaults) becomes today's, which holds the SAC baseline's section only and reads back.
    #[test]
    fn a_flat_baseline_config_becomes_todays() {
        let old = "algorithm = \"sac\"\nenv = \"lightsout-cursor\"\nnum_skills = 25\neval_seeds = 20\n\
                   [sac]\nhidden = [512, 512, 512]\nbatch_size = 256\nupdates_per_epoch = 16\n\
                   [baseline]\nupdates_per_epoch = 0.5\n[relabel]\nsac_p = 0.5\n";
        let err = migrate_config(old).unwrap_err();
        assert!(err.to_string().contains("[seads]"), "{err}");
        let old = old.replace("num_skills = 25\n", "");
        let new = migrate_config(&old).unwrap().unwrap();
        let config = TrainConfig::from_toml(&new).unwrap();
        assert_eq!(config.algorithm(), "sac");
        assert_eq!(
            config
                .section::<BaselineConfig>()
                .unwrap()
                .updates_per_epoch,
            0.5
        );
        assert_eq!(config.sac.hidden, [512, 512, 512]);
        assert!(
            !new.contains("[seads") && !new.contains("[baseline"),
            "{new}"
        );
        // Today's file is left alone.
        assert_eq!(migrate_config(&new).unwrap(), None);
    }

    #[test]
    fn a_manifest_keeps_its_comments_and_moves_its_overrides() {
        let old = "# a study\nname = \"s\"\n\n[[variant]]\nname = \"a\" # first\n\
                   overrides = { relabel = { sac_p = 0.0 } } # ablation\n\n\
                   [[variant]]\nname = \"b\"\n\
                   env_overrides = { \"lightsout-cursor\" = { num_skills = 30 } }\n\n\
                   [[variant]]\nname = \"c\"\noverrides = { algorithm = \"sac\", baseline = { eval_boards = 3 } }\n";
        let new = migrate_manifest(old).unwrap().unwrap();
        assert_eq!(
            new,
            "# a study\nname = \"s\"\n\n[[variant]]\nname = \"a\" # first\n\
             overrides = { seads = { relabel = { sac_p = 0.0 } } } # ablation\n\n\
             [[variant]]\nname = \"b\"\n\
             env_overrides = { lightsout-cursor = { seads = { num_skills = 30 } } }\n\n\
             [[variant]]\nname = \"c\"\noverrides = { algorithm = \"sac\", sac_baseline = { eval_boards = 3 } }\n"
        );
        assert_eq!(migrate_manifest(&new).unwrap(), None);
        assert_eq!(migrate_manifest("a = 1").unwrap(), None);
    }

    /// A table of three-word states gets a fourth word of zeros; its other tensors, and a table
    /// of four words, are left as they were.
    #[test]
    fn three_word_episode_tables_are_widened() {
        use tch::Tensor;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("episodes.safetensors");
        let z0 = Tensor::from_slice(&[1i64, 2, 3, -4, 5, 6]).view([2, 3]);
        let zt = Tensor::from_slice(&[7i64, 8, 9, 10, 11, 12]).view([2, 3]);
        let skills = Tensor::from_slice(&[3i64, 1]);
        let old = [("z0", z0), ("zt", zt), ("skills", skills)];
        Tensor::write_safetensors(&old, &path).unwrap();
        let new = migrate_episodes(&path).unwrap().unwrap();
        std::fs::write(&path, new).unwrap();
        let read: std::collections::BTreeMap<String, Tensor> = Tensor::read_safetensors(&path)
            .unwrap()
            .into_iter()
            .collect();
        let words = |name: &str| Vec::<i64>::try_from(read[name].flatten(0, -1)).unwrap();
        assert_eq!(read["z0"].size(), [2, 4]);
        assert_eq!(words("z0"), [1, 2, 3, 0, -4, 5, 6, 0]);
        assert_eq!(words("zt"), [7, 8, 9, 0, 10, 11, 12, 0]);
        assert_eq!(words("skills"), [3, 1]);
        assert!(migrate_episodes(&path).unwrap().is_none());
        // Neither three nor four words is an error.
        let two = Tensor::from_slice(&[1i64, 2]).view([1, 2]);
        Tensor::write_safetensors(&[("z0", two.copy()), ("zt", two)], &path).unwrap();
        assert!(migrate_episodes(&path).is_err());
    }

    #[test]
    fn a_bare_evaluation_list_becomes_a_record() {
        let bare = serde_json::to_string(&vec![seads_planner::DepthResult::new(1)]).unwrap();
        let new = migrate_evaluation(&bare).unwrap().unwrap();
        let record = seads_planner::EvaluationRecord::from_json(&new).unwrap();
        assert_eq!((record.checkpoint, record.protocol), (None, None));
        assert_eq!(record.results.len(), 1);
        assert_eq!(migrate_evaluation(&new).unwrap(), None);
    }
}
