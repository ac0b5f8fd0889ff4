//! The runs a report reads: sweeps (their index names each run's variant) and single run
//! directories, grouped by environment and variant.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::{fail, failure};
use crate::{Context as _, Result};
use seads_planner::{
    DepthResult, EvaluationKind, Evaluator, PlanModel, Protocol, STANDARD_DEPTHS, SearchLimits,
};
use seads_run::{MetricsRecord, TrainConfig};

use crate::evaluation::CheckpointEvaluation;
use crate::sweep::Sweep;

/// A run's evaluation with re-planning at depths beyond the standard ones (the paper's Fig.
/// S.7), at the end of training.
#[derive(Debug, Clone)]
pub struct DeepSearch {
    /// Its search limits (one set for all its depths).
    pub limits: SearchLimits,
    /// Boards per depth.
    pub boards: usize,
    /// Per depth, in order.
    pub results: Vec<DepthResult>,
}

/// One run, as read from its directory.
pub struct RunData {
    /// Run directory.
    pub dir: PathBuf,
    /// Where a copy of its data goes in a report: `<sweep>/<run dir in the sweep>` or, for a
    /// single run, its directory's name.
    pub copy_to: PathBuf,
    /// Variant (from the sweep; a single run is named by its directory).
    pub variant: String,
    /// Configuration.
    pub config: TrainConfig,
    /// Its number of skills K ([`crate::run_skills`]).
    pub skills: usize,
    /// The lines of its `metrics.jsonl`, whichever learner wrote them: skill coverage (SEADS),
    /// task success over training (the baselines), wall time and phases.
    pub lines: Vec<MetricsRecord>,
    /// Final task success of a baseline's policy acting alone, if any.
    pub policy: Option<Vec<DepthResult>>,
    /// Final task evaluation with re-planning, if any.
    pub replan: Option<Vec<DepthResult>>,
    /// Final task evaluation without re-planning, if any.
    pub plan_once: Option<Vec<DepthResult>>,
    /// The per-task file of the re-planning evaluation taken (`evaluation-replan-tasks.jsonl`
    /// for the standard protocol), in the run directory.
    pub replan_tasks: String,
    /// The protocol of each of these three final evaluations (re-planning, plan once, policy),
    /// in a few words ([`Protocol::label`]: `standard`, or how it departs from the standard
    /// one; `not recorded` for a record without its protocol).
    pub success_protocols: [Option<String>; 3],
    /// Final evaluations planning with a forward model fitted to the run's skills afterwards
    /// (`seads fit-model`), with re-planning and planning once, each with its protocol's label
    /// (`fitted-model`, and any other departure).
    pub fitted: [Option<(Vec<DepthResult>, String)>; 2],
    /// How well the forward model fitted to the run's skills explains held-out executions
    /// (`fitted-model/fit.json`), if one was fitted to its last checkpoint.
    pub fit: Option<seads_run::fitted::FitQuality>,
    /// Final task evaluations under action noise: (σ, with re-planning, per depth), in the
    /// order of their files' names.
    pub noisy: Vec<(f64, bool, Vec<DepthResult>)>,
    /// The deeper search (depths beyond the standard ones, with re-planning), if evaluated.
    pub deep: Option<DeepSearch>,
    /// Task success over training, if evaluated.
    pub over_training: Vec<CheckpointEvaluation>,
    /// The processors that trained it (`provenance.jsonl`; empty for older runs).
    pub processors: Vec<String>,
    /// The binaries that made the evaluations the tables take.
    pub evaluated_by: Evaluators,
    /// Evaluation files left out of the end-of-training tables because they evaluated an
    /// earlier checkpoint: one line each.
    pub evaluation_notes: Vec<String>,
    /// Evaluation files taken as the end of training although they do not record their
    /// checkpoint (written before evaluations did).
    pub unrecorded_evaluations: usize,
    /// Files of the run that could not be read, with why: such a run is left out of every
    /// table and listed as damaged.
    pub damage: Vec<String>,
    /// A sweep's task holds the run now (training, or evaluating after its last step): not
    /// finished, whatever its metrics say.
    pub busy: bool,
}

impl RunData {
    /// Whether training spent its budget and no task works on the run any more (a sweep's task
    /// evaluates a run after its last step).
    pub fn finished(&self) -> bool {
        self.env_steps() >= self.config.env_steps && !self.busy
    }

    /// Environment steps at the last evaluation (0 before the first).
    pub fn env_steps(&self) -> u64 {
        self.lines.last().map_or(0, |m| m.env_steps)
    }

    /// Skill coverage at the end of training.
    pub fn final_coverage(&self) -> Option<f64> {
        self.lines.last().and_then(|m| m.skill_coverage)
    }

    fn load(dir: &Path, variant: String, copy_to: PathBuf) -> Result<Self> {
        let config = seads_run::load_config(dir)?;
        let skills = crate::run_skills(&config)?;
        let mut damage = Vec::new();
        let lines = metrics_or_damage(dir, &mut damage);
        // The last epoch of training: an evaluation of the end of training names it.
        let last_epoch = lines.last().map(|m| m.epoch);
        let mut evaluation_notes = Vec::new();
        let mut unrecorded_evaluations = 0;
        let mut evaluated_by = Evaluators::default();
        let further = further_evaluations(dir, last_epoch, &mut damage, &mut evaluated_by);
        // A run's final evaluation of a kind on the standard depths: the standard protocol's
        // file (whatever protocol an older binary wrote there), else the one evaluation of
        // another protocol there is (a study that set its own boards or limits); several are
        // left out, since none of them is the run's. Each comes with its protocol's label.
        let mut replan_tasks = EvaluationKind::Replan.tasks_file(&STANDARD_DEPTHS, None);
        let mut evaluation = |kind: EvaluationKind| -> Result<Option<(Vec<DepthResult>, String)>> {
            let file = kind.results_file(&STANDARD_DEPTHS, None);
            let record = match crate::evaluation::read_evaluation(&dir.join(&file)) {
                Ok(Some(record)) => record,
                Ok(None) => {
                    let others: Vec<&(Protocol, Vec<DepthResult>)> = further
                        .iter()
                        .filter(|(p, _)| {
                            p.kind == kind
                                && p.tasks.depths == STANDARD_DEPTHS
                                && p.action_noise.is_none()
                                && p.model == PlanModel::Own
                        })
                        .collect();
                    return Ok(match others.as_slice() {
                        [] => None,
                        [(protocol, results)] => {
                            if kind == EvaluationKind::Replan {
                                replan_tasks = protocol.tasks_file(None);
                            }
                            Some((results.clone(), protocol.label()))
                        }
                        several => {
                            let labels: Vec<String> =
                                several.iter().map(|(p, _)| p.label()).collect();
                            evaluation_notes.push(format!(
                                "{} evaluations of other protocols ({}) and none of the standard \
                                 one: left out",
                                kind.name(),
                                labels.join("; ")
                            ));
                            None
                        }
                    });
                }
                Err(e) => {
                    damage.push(format!("{e:#}"));
                    return Ok(None);
                }
            };
            let protocol = record
                .protocol
                .as_ref()
                .map_or_else(|| "not recorded".to_owned(), Protocol::label);
            match record.checkpoint {
                Some(c) if Some(c.epoch) != last_epoch => {
                    evaluation_notes.push(format!(
                        "`{file}` evaluated epoch {}, not the end of training (epoch {}): left out",
                        c.epoch,
                        last_epoch.map_or("unknown".into(), |e| e.to_string())
                    ));
                    Ok(None)
                }
                Some(_) => {
                    evaluated_by.add(record.evaluated_by);
                    Ok(Some((record.results, protocol)))
                }
                None => {
                    unrecorded_evaluations += 1;
                    evaluated_by.add(record.evaluated_by);
                    Ok(Some((record.results, protocol)))
                }
            }
        };
        let (replan, plan_once, policy) = (
            evaluation(EvaluationKind::Replan)?,
            evaluation(EvaluationKind::PlanOnce)?,
            evaluation(EvaluationKind::Policy)?,
        );
        let success_protocols = [&replan, &plan_once, &policy]
            .map(|e| e.as_ref().map(|(_, protocol)| protocol.clone()));
        let [replan, plan_once, policy] =
            [replan, plan_once, policy].map(|e| e.map(|(results, _)| results));
        let (noisy, deep) = (noisy_evaluations(&further), deep_search(&further));
        let fitted = [EvaluationKind::Replan, EvaluationKind::PlanOnce]
            .map(|kind| fitted_evaluation(&further, kind, &mut evaluation_notes));
        let fit = match seads_run::fitted::read_fit_record(dir) {
            Ok(Some(record)) if Some(record.checkpoint.epoch) == last_epoch => Some(record.quality),
            Ok(Some(record)) => {
                evaluation_notes.push(format!(
                    "the fitted model is of epoch {}, not the end of training: left out",
                    record.checkpoint.epoch
                ));
                None
            }
            Ok(None) => None,
            Err(e) => {
                damage.push(format!("{e:#}"));
                None
            }
        };
        let over_training = crate::evaluation::read_over_training(dir)?;
        for line in &over_training {
            evaluated_by.add(line.evaluated_by.iter().cloned().collect());
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            copy_to,
            variant,
            replan,
            plan_once,
            policy,
            success_protocols,
            fitted,
            fit,
            replan_tasks,
            noisy,
            deep,
            evaluation_notes,
            unrecorded_evaluations,
            damage,
            busy: crate::sweep::is_claimed(dir),
            over_training,
            processors: crate::provenance::Provenance::processors(dir)
                .doing(|| format!("reading the provenance of {}", dir.display()))?,
            evaluated_by,
            config,
            skills,
            lines,
        })
    }
}

/// The run's final evaluation of `kind` on the standard depths planning with a fitted model, with
/// its protocol's label; several (of different limits) are left out with a note, since none of
/// them is the run's.
fn fitted_evaluation(
    further: &[(Protocol, Vec<DepthResult>)],
    kind: EvaluationKind,
    notes: &mut Vec<String>,
) -> Option<(Vec<DepthResult>, String)> {
    let found: Vec<&(Protocol, Vec<DepthResult>)> = further
        .iter()
        .filter(|(p, _)| {
            p.kind == kind
                && p.model == PlanModel::Fitted
                && p.tasks.depths == STANDARD_DEPTHS
                && p.action_noise.is_none()
        })
        .collect();
    match found.as_slice() {
        [] => None,
        [(protocol, results)] => Some((results.clone(), protocol.label())),
        several => {
            let labels: Vec<String> = several.iter().map(|(p, _)| p.label()).collect();
            notes.push(format!(
                "{} evaluations with a fitted model of several protocols ({}): left out",
                kind.name(),
                labels.join("; ")
            ));
            None
        }
    }
}

/// The binaries that made a run's evaluations, each once in the order met, and how many of its
/// evaluation files name none (written before evaluation files did).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Evaluators {
    /// The binaries named.
    pub named: Vec<Evaluator>,
    /// Evaluation files (or over-training lines) that name no binary.
    pub unnamed: usize,
}

impl Evaluators {
    /// Adds what one evaluation file names.
    pub(crate) fn add(&mut self, by: Vec<Evaluator>) {
        if by.is_empty() {
            self.unnamed += 1;
        }
        for evaluator in by {
            if !self.named.contains(&evaluator) {
                self.named.push(evaluator);
            }
        }
    }
}

/// The run's evaluations (planning and policy), other than the standard ones, that evaluated its
/// last checkpoint on the test split with the standard seeds (`evaluation-replan-noise-0.05.json`,
/// `evaluation-replan-depths-6-10.json`, `evaluation-replan-boards-2.json`, …), in the order of
/// their files' names, with the binaries they name added to `evaluated_by`; an unreadable one is
/// damage.
fn further_evaluations(
    dir: &Path,
    last_epoch: Option<u64>,
    damage: &mut Vec<String>,
    evaluated_by: &mut Evaluators,
) -> Vec<(Protocol, Vec<DepthResult>)> {
    let standard_files = [
        EvaluationKind::Replan,
        EvaluationKind::PlanOnce,
        EvaluationKind::Policy,
    ]
    .map(|kind| kind.results_file(&STANDARD_DEPTHS, None));
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| {
            n.starts_with("evaluation-")
                && n.ends_with(".json")
                && !n.contains("-epoch-")
                && !standard_files.contains(n)
        })
        .collect();
    names.sort();
    let mut found = Vec::new();
    for name in names {
        let record = match crate::evaluation::read_evaluation(&dir.join(&name)) {
            Ok(Some(record)) => record,
            Ok(None) => continue,
            Err(e) => {
                damage.push(format!("{e:#}"));
                continue;
            }
        };
        let at_end = record
            .checkpoint
            .is_some_and(|c| Some(c.epoch) == last_epoch);
        if let (Some(protocol), true) = (record.protocol, at_end)
            && protocol.tasks.split == seads_games::Split::Test
            && protocol.tasks.seed.is_none()
        {
            evaluated_by.add(record.evaluated_by);
            found.push((protocol, record.results));
        }
    }
    found
}

/// The evaluations of the standard depths under action noise among `further`: (σ, with
/// re-planning, per depth).
fn noisy_evaluations(
    further: &[(Protocol, Vec<DepthResult>)],
) -> Vec<(f64, bool, Vec<DepthResult>)> {
    further
        .iter()
        .filter(|(p, _)| p.tasks.depths == STANDARD_DEPTHS)
        .filter_map(|(p, results)| {
            Some((
                p.action_noise?,
                p.kind == EvaluationKind::Replan,
                results.clone(),
            ))
        })
        .collect()
}

/// The deeper search among `further`: evaluations with re-planning and without noise of depths
/// other than the standard ones, merged per depth (the first file of a depth counts).
fn deep_search(further: &[(Protocol, Vec<DepthResult>)]) -> Option<DeepSearch> {
    let mut deep: Option<DeepSearch> = None;
    for (protocol, results) in further {
        let Some(limits) = protocol.limits else {
            continue;
        };
        if protocol.kind != EvaluationKind::Replan
            || protocol.action_noise.is_some()
            || protocol.tasks.depths == STANDARD_DEPTHS
        {
            continue;
        }
        let deep = deep.get_or_insert_with(|| DeepSearch {
            limits,
            boards: protocol.tasks.boards,
            results: Vec::new(),
        });
        if deep.limits != limits || deep.boards != protocol.tasks.boards {
            continue;
        }
        for r in results {
            if !deep.results.iter().any(|d| d.depth == r.depth) {
                deep.results.push(r.clone());
            }
        }
    }
    if let Some(deep) = &mut deep {
        deep.results.sort_by_key(|r| r.depth);
    }
    deep
}

/// The metrics lines of the run in `dir`; none without a metrics file (not started), and none
/// with the reason added to `damage` when the file exists but cannot be read.
fn metrics_or_damage(dir: &Path, damage: &mut Vec<String>) -> Vec<MetricsRecord> {
    match seads_run::store::read_metrics_as(dir) {
        Ok(lines) => lines,
        Err(e) => {
            if dir.join("metrics.jsonl").exists() {
                damage.push(format!("{e:#}"));
            }
            Vec::new()
        }
    }
}

/// What the report reads.
pub struct Collection {
    /// Every run found.
    pub runs: Vec<RunData>,
    /// The reference variant (the sweeps' or the user's choice).
    pub reference: Option<String>,
    /// Names of the sweeps read.
    pub sweeps: Vec<String>,
    /// Their directories.
    pub sweep_dirs: Vec<PathBuf>,
    /// Run directories whose configuration cannot be read, with why (left out, listed).
    pub unreadable: Vec<(PathBuf, String)>,
    /// Runs of a sweep's index without a directory here: a copy holds finished runs only.
    pub absent: usize,
}

/// Reads the sweeps and runs in `inputs`.
pub fn collect(inputs: &[PathBuf]) -> Result<Collection> {
    let mut collection = Collection {
        runs: Vec::new(),
        reference: None,
        sweeps: Vec::new(),
        sweep_dirs: Vec::new(),
        unreadable: Vec::new(),
        absent: 0,
    };
    // Each run once, however often and by whichever path it is given (a run named twice, or in
    // a sweep named twice, is one run).
    let mut seen = std::collections::BTreeSet::new();
    let mut first_time =
        |dir: &Path| seen.insert(std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()));
    for input in inputs {
        if input.join(crate::sweep::INDEX).is_file() {
            let sweep = Sweep::load(input)?;
            let mut new_runs = false;
            for run in &sweep.runs {
                let dir = input.join(&run.dir);
                if !dir.exists() {
                    collection.absent += 1;
                    continue;
                }
                if !first_time(&dir) {
                    continue;
                }
                new_runs = true;
                match RunData::load(
                    &dir,
                    run.variant.clone(),
                    Path::new(&sweep.name).join(&run.dir),
                ) {
                    Ok(data) => collection.runs.push(data),
                    Err(e) => collection.unreadable.push((dir, format!("{e:#}"))),
                }
            }
            collection.reference.get_or_insert(sweep.reference.clone());
            if new_runs || !collection.sweeps.contains(&sweep.name) {
                collection.sweeps.push(sweep.name);
                collection.sweep_dirs.push(input.clone());
            }
        } else if input.join("config.toml").is_file() {
            if !first_time(input) {
                continue;
            }
            // Named by the directory itself, also when given as `.` or `..`.
            let real = std::fs::canonicalize(input).unwrap_or_else(|_| input.clone());
            let name = real.file_name().map_or_else(
                || input.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            match RunData::load(input, name.clone(), PathBuf::from(name)) {
                Ok(data) => collection.runs.push(data),
                Err(e) => collection
                    .unreadable
                    .push((input.clone(), format!("{e:#}"))),
            }
        } else if input.is_dir() {
            fail!(
                "{} is neither a sweep (sweep.json) nor a run directory (config.toml)",
                input.display()
            );
        } else if input.exists() {
            fail!(
                "{} is a file, not a sweep or run directory",
                input.display()
            );
        } else {
            fail!("{} does not exist", input.display());
        }
    }
    if collection.runs.is_empty() {
        match collection.unreadable.first() {
            Some((dir, why)) => fail!(
                "no runs to report on: {} cannot be read: {why}",
                dir.display()
            ),
            None => fail!("no runs to report on"),
        }
    }
    Ok(collection)
}

/// The runs of one environment and variant: a row of the tables.
pub struct Group<'a> {
    /// Environment.
    pub env: String,
    /// Variant.
    pub variant: String,
    /// Finished runs.
    pub runs: Vec<&'a RunData>,
}

/// Finished runs grouped by environment, then variant (in the order first seen); the runs of a
/// group must share the environment's options (board size, spacing, depths), since a row of
/// the table is one environment. Unfinished runs are returned apart; damaged runs are in neither.
pub fn group(runs: &[RunData]) -> Result<(Vec<Group<'_>>, Vec<&RunData>)> {
    let mut groups: Vec<Group<'_>> = Vec::new();
    let mut unfinished = Vec::new();
    let mut env_configs: BTreeMap<(String, String), (String, PathBuf)> = BTreeMap::new();
    for run in runs {
        if !run.damage.is_empty() {
            continue; // listed apart by the report, in no table
        }
        if !run.finished() {
            unfinished.push(run);
            continue;
        }
        let key = (run.config.env.clone(), run.variant.clone());
        let options = toml::to_string(&run.config.env_config)?;
        match env_configs.get(&key) {
            Some((other, first)) if *other != options => {
                return Err(failure!(
                    "variant {:?} mixes different {} environments in one table row: {} and {} differ in their env_config",
                    run.variant,
                    run.config.env,
                    first.display(),
                    run.dir.display()
                ));
            }
            Some(_) => {}
            None => {
                env_configs.insert(key.clone(), (options, run.dir.clone()));
            }
        }
        match groups
            .iter_mut()
            .find(|g| g.env == key.0 && g.variant == key.1)
        {
            Some(g) => g.runs.push(run),
            None => groups.push(Group {
                env: key.0,
                variant: key.1,
                runs: vec![run],
            }),
        }
    }
    Ok((groups, unfinished))
}

/// A run with nothing in it but its name and the default config, for tests to fill in.
#[cfg(test)]
pub(crate) fn bare_run(seed: u32) -> RunData {
    RunData {
        dir: format!("seed-{seed}").into(),
        copy_to: format!("seed-{seed}").into(),
        variant: "seads".into(),
        config: TrainConfig::default(),
        skills: 25,
        lines: Vec::new(),
        policy: None,
        replan: None,
        plan_once: None,
        success_protocols: [None, None, None],
        fitted: [None, None],
        fit: None,
        replan_tasks: EvaluationKind::Replan.tasks_file(&STANDARD_DEPTHS, None),
        noisy: Vec::new(),
        deep: None,
        evaluated_by: Evaluators::default(),
        over_training: Vec::new(),
        processors: Vec::new(),
        evaluation_notes: Vec::new(),
        unrecorded_evaluations: 0,
        damage: Vec::new(),
        busy: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every study committed under `docs/results` reads back whole: each sweep's runs, and each
    /// run outside a sweep, load (configuration as a run directory is read, metrics, evaluation
    /// files, provenance) with no run damaged or unreadable, so that every report can be made
    /// again from its data by the current code.
    #[test]
    fn every_committed_study_reads_back_without_damage() {
        let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/results");
        let in_a_sweep = |dir: &Path| {
            dir.ancestors()
                .take_while(|a| *a != results)
                .any(|a| a.join("sweep.json").is_file())
        };
        let mut inputs: Vec<PathBuf> = walkdir::WalkDir::new(&results)
            .into_iter()
            .map(|e| e.unwrap().into_path())
            .filter_map(|path| {
                let dir = path.parent()?.to_path_buf();
                let name = path.file_name()?;
                let sweep = name == "sweep.json";
                let lone_run = name == "config.toml" && !in_a_sweep(&dir);
                (sweep || lone_run).then_some(dir)
            })
            .collect();
        inputs.sort();
        assert!(inputs.len() >= 20, "{inputs:?}");
        let mut runs = 0;
        for input in &inputs {
            let collection = collect(std::slice::from_ref(input))
                .unwrap_or_else(|e| panic!("{}: {e:#}", input.display()));
            assert!(
                collection.unreadable.is_empty(),
                "{}: {:?}",
                input.display(),
                collection.unreadable
            );
            for run in &collection.runs {
                assert!(
                    run.damage.is_empty(),
                    "{}: {:?}",
                    run.dir.display(),
                    run.damage
                );
            }
            runs += collection.runs.len();
        }
        assert!(runs > 250, "{runs} runs");
    }
}
