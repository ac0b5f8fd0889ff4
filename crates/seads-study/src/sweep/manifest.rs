//! Study manifests: environments × variants × seeds, where a variant is a name plus overrides of
//! the preset in the keys of `configs/*.toml`. A manifest expands into one full [`TrainConfig`]
//! per run; every way it can be wrong is a one-line error found before anything is written.

use std::collections::BTreeMap;

use crate::Result;
use crate::error::{fail, failure};
use seads_embodiment::env_names;
use seads_run::{SeadsConfig, Section, TrainConfig};
use serde::{Deserialize, Serialize};

/// A study, as written in `experiments/*.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Name of the study (a folder name in `docs/results/`).
    pub name: String,
    /// What the study shows, for the report.
    #[serde(default)]
    pub description: String,
    /// Environments (see `seads envs`); each run starts from the environment's preset.
    pub environments: Vec<String>,
    /// Seeds; every variant is trained with each.
    pub seeds: Vec<u64>,
    /// The variant the others are tested against in the report (default: the first).
    #[serde(default)]
    pub reference: Option<String>,
    /// Overrides of every run, applied before the variant's (e.g. a shorter budget).
    #[serde(default)]
    pub overrides: toml::Table,
    /// What `seads sweep run` evaluates after training.
    #[serde(default)]
    pub evaluation: EvaluationPlan,
    /// The variants.
    #[serde(rename = "variant")]
    pub variants: Vec<Variant>,
}

/// One variant: a name and overrides of the preset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Name (a folder name: letters, digits, `-` and `_`).
    pub name: String,
    /// Overrides for every environment, in the keys of `configs/*.toml`.
    #[serde(default)]
    pub overrides: toml::Table,
    /// Overrides for one environment, applied after `overrides` (e.g. K = 30 on LightsOut and
    /// 15 on TileSwap for "more skills").
    #[serde(default)]
    pub env_overrides: BTreeMap<String, toml::Table>,
}

/// Task-success evaluation of each run after training (SPEC §4.4): test boards of depths 1–5.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EvaluationPlan {
    /// Evaluate the final agent with and without re-planning (`evaluation-*.json`).
    pub last: bool,
    /// Also evaluate every N-th kept checkpoint into `evaluation-over-training.jsonl` (0: none).
    pub every: usize,
    /// Boards per depth.
    pub boards: usize,
    /// Also stop each search after this many seconds (none by default: a clock makes the
    /// outcome depend on the machine's speed and load; the authors used 60).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timeout: Option<f64>,
    /// Stop each search after expanding this many states (default 2²², the same on every
    /// machine).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_expanded: Option<usize>,
    /// Which plan each search returns: `most-likely` (default) or `first-found` (the paper's).
    pub plan: seads_planner::PlanChoice,
    /// Also fit SEADS's forward model to each skill learner's final skills (`seads fit-model`,
    /// its standard settings) and evaluate planning with it, with and without re-planning
    /// (`evaluation-*-fitted-model.json`): how learners compare by their skills alone.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub fitted_model: bool,
}

impl Default for EvaluationPlan {
    fn default() -> Self {
        Self {
            last: true,
            every: 0,
            boards: 20,
            timeout: None,
            max_expanded: Some(seads_planner::DEFAULT_MAX_EXPANDED),
            plan: seads_planner::PlanChoice::MostLikely,
            fitted_model: false,
        }
    }
}

impl EvaluationPlan {
    /// The limits of each search.
    pub fn limits(&self) -> seads_planner::SearchLimits {
        seads_planner::SearchLimits {
            timeout_s: self.timeout,
            max_expanded: self.max_expanded,
            plan: self.plan,
            search: seads_planner::Search::Breadth,
            memory_limit_mib: None,
        }
    }
}

/// One run of a study.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedRun {
    /// Environment.
    pub env: String,
    /// Variant name.
    pub variant: String,
    /// Seed.
    pub seed: u64,
    /// The full configuration.
    pub config: TrainConfig,
}

impl PlannedRun {
    /// The run's folder, relative to the sweep directory.
    pub fn rel_dir(&self) -> String {
        format!("runs/{}/{}/seed-{}", self.env, self.variant, self.seed)
    }
}

/// Keys a variant may not set: the study's axes set them.
const AXIS_KEYS: [&str; 2] = ["env", "seed"];

impl Manifest {
    /// Parses and validates a manifest; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let manifest: Self = toml::from_str(text)
            .map_err(|e| failure!("{origin}: {}", e.message().trim().replace('\n', " ")))?;
        manifest
            .validate()
            .map_err(|e| failure!("{origin}: {e:#}"))?;
        Ok(manifest)
    }

    /// The variant the others are compared with.
    pub fn reference(&self) -> &str {
        self.reference
            .as_deref()
            .or(self.variants.first().map(|v| v.name.as_str()))
            .unwrap_or("")
    }

    fn validate(&self) -> Result<()> {
        if !is_name(&self.name) {
            fail!(
                "the study name {:?} must be letters, digits, '-' or '_'",
                self.name
            );
        }
        let known = env_names();
        let mut listed = std::collections::BTreeSet::new();
        for env in &self.environments {
            if !known.contains(&env.as_str()) {
                fail!(
                    "unknown environment {env:?}; valid environments: {}",
                    known.join(", ")
                );
            }
            // One run directory per environment: listed twice, its runs would be counted twice.
            if !listed.insert(env.as_str()) {
                fail!("environment {env:?} is listed twice");
            }
        }
        let mut names = std::collections::BTreeSet::new();
        for v in &self.variants {
            if !is_name(&v.name) {
                fail!(
                    "variant name {:?} must be letters, digits, '-' or '_'",
                    v.name
                );
            }
            if !names.insert(v.name.as_str()) {
                fail!("duplicate variant name {:?}", v.name);
            }
            for env in v.env_overrides.keys() {
                if !self.environments.contains(env) {
                    fail!(
                        "variant {:?} overrides environment {env:?}, which the study does not train",
                        v.name
                    );
                }
            }
        }
        if let Some(reference) = &self.reference
            && !names.contains(reference.as_str())
        {
            fail!("the reference variant {reference:?} is not a variant of the study");
        }
        let mut seeds = self.seeds.clone();
        seeds.sort_unstable();
        seeds.dedup();
        if seeds.len() != self.seeds.len() {
            fail!("a seed is listed twice");
        }
        if self.environments.is_empty() || self.seeds.is_empty() || self.variants.is_empty() {
            fail!(
                "the manifest expands to no run: it needs at least one environment, one seed and one variant"
            );
        }
        let e = &self.evaluation;
        let bad_timeout = e.timeout.is_some_and(|t| !(t.is_finite() && t > 0.0));
        if e.boards == 0 || bad_timeout || e.max_expanded == Some(0) {
            fail!(
                "evaluation.boards and evaluation.max_expanded must be at least 1 and \
                 evaluation.timeout above 0"
            );
        }
        if let Some(problem) = seads_planner::TaskSet::standard(e.boards).problem() {
            fail!("evaluation.boards = {}: {problem}", e.boards);
        }
        // Expanding checks every override against the configuration's keys and values.
        self.expand()?;
        Ok(())
    }

    /// Every run: environments, then seeds, then variants, so that a sweep stopped part way
    /// has the same number of seeds of every variant.
    pub fn expand(&self) -> Result<Vec<PlannedRun>> {
        let mut runs = Vec::new();
        for env in &self.environments {
            for &seed in &self.seeds {
                for variant in &self.variants {
                    let config = self.config(env, variant, seed)?;
                    runs.push(PlannedRun {
                        env: env.clone(),
                        variant: variant.name.clone(),
                        seed,
                        config,
                    });
                }
            }
        }
        Ok(runs)
    }

    /// The preset of `env` with the study's, the variant's and the environment's overrides.
    /// A layer that sets `algorithm` (as `"sac"`) starts from that algorithm's preset.
    fn config(&self, env: &str, variant: &Variant, seed: u64) -> Result<TrainConfig> {
        let env_layer = variant.env_overrides.get(env);
        let named = [Some(&self.overrides), Some(&variant.overrides), env_layer]
            .into_iter()
            .flatten()
            .filter_map(|layer| layer.get("algorithm").and_then(|v| v.as_str()))
            .next_back();
        let algorithm = match named {
            Some(name) if seads_run::section_name(name).is_none() => fail!(
                "variant {:?}: unknown algorithm {name:?} (one of {})",
                variant.name,
                seads_run::learner_names().join(", ")
            ),
            Some(name) => name,
            None => SeadsConfig::ALGORITHM,
        };
        let preset = TrainConfig::preset_for(env, algorithm)
            .map_err(|e| failure!("variant {:?}: {e}", variant.name))?;
        let mut table: toml::Table = toml::from_str(&preset.to_toml())?;
        let layers = [
            ("overrides", &self.overrides),
            ("variant overrides", &variant.overrides),
        ];
        for (what, layer) in layers
            .into_iter()
            .chain(env_layer.map(|l| ("environment overrides", l)))
        {
            for key in AXIS_KEYS {
                if layer.contains_key(key) {
                    fail!(
                        "variant {:?}: {what} may not set `{key}` (the study's axes set it)",
                        variant.name
                    );
                }
            }
            seads_run::merge_toml(&mut table, layer);
        }
        table.insert("seed".into(), toml::Value::Integer(seed as i64));
        let config = TrainConfig::from_table(table)
            .and_then(|config| config.validate().map(|()| config))
            .map_err(|e| failure!("variant {:?} on {env}: {e}", variant.name))?;
        Ok(config)
    }
}

/// Whether `name` may name a study or a variant (a folder's name).
fn is_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = r#"
name = "small"
environments = ["lightsout-cursor", "tileswap-cursor"]
seeds = [1, 2]
overrides = { env_steps = 1000 }

[[variant]]
name = "seads"

[[variant]]
name = "no-relabelling"
overrides = { seads = { relabel = { skill_model_p = 0.0, sac_p = 0.0 } } }

[[variant]]
name = "more-skills"
env_overrides = { "lightsout-cursor" = { seads = { num_skills = 30 } }, "tileswap-cursor" = { seads = { num_skills = 15 } } }
"#;

    #[test]
    fn a_manifest_expands_into_every_run_with_its_overrides() {
        let m = Manifest::parse(SMALL, "small.toml").unwrap();
        let runs = m.expand().unwrap();
        assert_eq!(runs.len(), 2 * 2 * 3);
        assert_eq!(m.reference(), "seads");
        // Order: environment, seed, variant.
        assert_eq!(
            (runs[3].env.as_str(), runs[3].seed, runs[3].variant.as_str()),
            ("lightsout-cursor", 2, "seads")
        );
        for run in &runs {
            assert_eq!(run.config.env, run.env);
            assert_eq!(run.config.seed, run.seed);
            assert_eq!(run.config.env_steps, 1000);
            let preset = TrainConfig::preset(&run.env).unwrap();
            // Untouched keys keep the preset's values (a nested table is merged, not replaced).
            assert_eq!(run.config.sac, preset.sac);
            match run.variant.as_str() {
                "no-relabelling" => {
                    assert_eq!(run.config.seads().unwrap().relabel.sac_p, 0.0);
                    assert_eq!(run.config.seads().unwrap().relabel.skill_model_p, 0.0);
                    assert_eq!(
                        run.config.seads().unwrap().relabel.kind,
                        preset.seads().unwrap().relabel.kind
                    );
                }
                "more-skills" => assert_eq!(
                    run.config.seads().unwrap().num_skills,
                    Some(if run.env == "lightsout-cursor" {
                        30
                    } else {
                        15
                    })
                ),
                _ => assert_eq!(
                    run.config.seads().unwrap().relabel,
                    preset.seads().unwrap().relabel
                ),
            }
        }
    }

    #[test]
    fn every_bad_manifest_is_one_line_naming_the_problem() {
        let cases = [
            (
                SMALL.replace("env_steps = 1000", "env_stepz = 1000"),
                "unknown field `env_stepz`",
            ),
            (
                SMALL.replace("\"tileswap-cursor\"]", "\"tileswap-cursr\"]"),
                "unknown environment \"tileswap-cursr\"",
            ),
            (
                SMALL.replace("name = \"more-skills\"", "name = \"seads\""),
                "duplicate variant name \"seads\"",
            ),
            (
                SMALL.replace("seeds = [1, 2]", "seeds = []"),
                "expands to no run",
            ),
            (
                SMALL.replace("sac_p = 0.0 }", "sac_p = 2.0 }"),
                "seads.relabel.sac_p must lie in [0, 1]",
            ),
            (
                SMALL.replace("env_steps = 1000", "seed = 3"),
                "may not set `seed`",
            ),
            (
                SMALL.replace("seeds = [1, 2]", "seeds = [1, 1]"),
                "listed twice",
            ),
            (
                SMALL.replace(
                    "environments = [\"lightsout-cursor\"",
                    "environments = [\"lightsout-cursor\", \"lightsout-cursor\"",
                ),
                "environment \"lightsout-cursor\" is listed twice",
            ),
            (
                SMALL.replace("name = \"small\"", "name = \"small\"\nreference = \"sead\""),
                "reference variant \"sead\"",
            ),
            (
                SMALL.replace(
                    "{ seads = { num_skills = 15 } } }",
                    "{ seads = { num_skills = 15 } }, \"lightsout-reacher\" = {} }",
                ),
                "does not train",
            ),
            (
                SMALL.replace(
                    "overrides = { env_steps = 1000 }",
                    "overrides = { env_steps = 1000, algorithm = \"ppo\" }",
                ),
                "unknown algorithm \"ppo\" (one of diayn, hac, sac, seads)",
            ),
        ];
        for (text, expected) in cases {
            let e = Manifest::parse(&text, "m.toml").unwrap_err().to_string();
            assert!(e.contains(expected), "{e:?} should say {expected:?}");
            assert!(!e.contains('\n'), "{e:?} is one line");
        }
    }

    /// Every manifest of `experiments/` and every study's committed copy (in today's layout:
    /// `seads migrate` rewrote the older ones) expands into valid runs.
    #[test]
    fn every_shipped_and_committed_manifest_expands() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let experiments = walkdir::WalkDir::new(root.join("experiments")).max_depth(1);
        let committed = walkdir::WalkDir::new(root.join("docs/results"));
        let manifests: Vec<std::path::PathBuf> = experiments
            .into_iter()
            .chain(committed)
            .map(|entry| entry.unwrap().into_path())
            .filter(|p| {
                p.extension().is_some_and(|e| e == "toml")
                    && (p.starts_with(root.join("experiments"))
                        || p.file_name().is_some_and(|n| n == "manifest.toml"))
            })
            .collect();
        assert!(manifests.len() > 20, "{}", manifests.len());
        for path in &manifests {
            let text = std::fs::read_to_string(path).unwrap();
            let runs = Manifest::parse(&text, "m.toml")
                .and_then(|m| m.expand())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(!runs.is_empty(), "{}", path.display());
        }
    }

    #[test]
    fn the_shipped_manifests_expand_to_the_paper_s_studies() {
        let shipped = [
            (
                include_str!("../../../../experiments/table1.toml"),
                2 * 7 * 5,
            ),
            (
                include_str!("../../../../experiments/table1-arms.toml"),
                4 * 7 * 5,
            ),
            (include_str!("../../../../experiments/vic.toml"), 2 * 4 * 3),
            (include_str!("../../../../experiments/arms.toml"), 5 * 2),
            (
                include_str!("../../../../experiments/arms-reacher.toml"),
                2 * 2 * 3,
            ),
            (
                include_str!("../../../../experiments/arms-jaco.toml"),
                2 * 3,
            ),
            (
                include_str!("../../../../experiments/board-size.toml"),
                5 * 5,
            ),
            (
                include_str!("../../../../experiments/baselines.toml"),
                2 * 3 * 5,
            ),
            (
                include_str!("../../../../experiments/hac-grid-cursor.toml"),
                2 * 64 * 5,
            ),
            (
                include_str!("../../../../experiments/hac-grid.toml"),
                4 * 16 * 5,
            ),
            (
                include_str!("../../../../experiments/sac-grid.toml"),
                6 * 9 * 5,
            ),
            // Two boards, three learners, three seeds.
            (
                include_str!("../../../../experiments/diayn.toml"),
                2 * 3 * 3,
            ),
        ];
        for (text, count) in shipped {
            let m = Manifest::parse(text, "experiments").unwrap();
            let runs = m.expand().unwrap();
            assert_eq!(runs.len(), count, "{}", m.name);
            // Only the study of learners without a model of their own plans with fitted ones.
            assert_eq!(m.evaluation.fitted_model, m.name == "diayn", "{}", m.name);
            assert_eq!(
                m.reference(),
                runs[0].variant,
                "{}: the reference comes first",
                m.name
            );
            for run in &runs {
                // Each variant changes only what its name says (SPEC §3.9, §3.10, §5.1).
                let hac_grid = m.name.starts_with("hac-grid");
                let algorithm = if m.name == "sac-grid" || run.variant == "sac" {
                    "sac"
                } else if run.variant == "diayn" {
                    "diayn"
                } else if hac_grid || run.variant == "hac" {
                    "hac"
                } else {
                    "seads"
                };
                let preset = TrainConfig::preset_for(&run.env, algorithm).unwrap();
                let mut expected = preset.clone();
                expected.seed = run.seed;
                let c = &run.config;
                // SEADS's section changed as `edit` does.
                let seads = |expected: &mut TrainConfig, edit: &dyn Fn(&mut SeadsConfig)| {
                    expected.edit(|s: &mut SeadsConfig| edit(s)).unwrap()
                };
                match run.variant.as_str() {
                    "seads" | "size-5" | "sac" | "hac" | "diayn" => {}
                    v if hac_grid => {
                        // t<tau_RB>-l<alpha_low>-h<alpha_high>.
                        let (t, rest) = v[1..].split_once("-l").unwrap();
                        let (low, high) = rest.split_once("-h").unwrap();
                        expected
                            .edit(|hac: &mut seads_run::HacConfig| {
                                hac.temperature = t.parse().unwrap();
                                hac.alpha_high = high.parse().unwrap();
                            })
                            .unwrap();
                        expected.sac.alpha = low.parse().unwrap();
                    }
                    v if m.name == "sac-grid" => {
                        // n<N>-a<alpha>, N with "_" for ".".
                        let (n, a) = v[1..].split_once("-a").unwrap();
                        expected
                            .edit(|sac: &mut seads_run::BaselineConfig| {
                                sac.updates_per_epoch = n.replace('_', ".").parse().unwrap();
                            })
                            .unwrap();
                        expected.sac.alpha = a.parse().unwrap();
                    }
                    "no-second-best-norm" => seads(&mut expected, &|s| {
                        s.reward.normalisation = seads_run::Normalisation::LogK;
                    }),
                    "no-novelty-bonus" => {
                        seads(&mut expected, &|s| s.reward.novelty_bonus = false);
                    }
                    "no-relabelling" => seads(&mut expected, &|s| {
                        (s.relabel.skill_model_p, s.relabel.sac_p) = (0.0, 0.0);
                    }),
                    "no-forward-model-relabelling" => {
                        seads(&mut expected, &|s| s.relabel.skill_model_p = 0.0);
                    }
                    "no-sac-relabelling" => seads(&mut expected, &|s| s.relabel.sac_p = 0.0),
                    "more-skills" => {
                        let k = if run.env.starts_with("lightsout") {
                            30
                        } else {
                            15
                        };
                        seads(&mut expected, &|s| s.num_skills = Some(k));
                    }
                    v if v.starts_with("vic") => seads(&mut expected, &|s| {
                        s.skill_model.kind = seads_run::SkillModelKind::Vic;
                        s.reward.novelty_bonus = false;
                        if v != "vic-sbn" {
                            s.reward.normalisation = seads_run::Normalisation::LogK;
                        }
                        if v != "vic-relabelling" {
                            (s.relabel.skill_model_p, s.relabel.sac_p) = (0.0, 0.0);
                        }
                    }),
                    v if v.starts_with("size-") => expected.env_config = c.env_config.clone(),
                    other => panic!("unexpected variant {other}"),
                }
                if m.name == "board-size" {
                    expected.env_steps = 1_500_000;
                }
                assert_eq!(c, &expected, "{} / {} / {}", m.name, run.env, run.variant);
            }
        }
    }
}
