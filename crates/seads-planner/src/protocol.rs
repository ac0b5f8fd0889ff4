//! What an evaluation is, in one place: its tasks (the boards and environment seeds of each
//! solution depth), its search limits, which checkpoint it evaluated, and the names of the files
//! it leaves in a run directory. Planning, policy, robot and over-training evaluations all take
//! their tasks from [`TaskSet::seeds`], so two evaluations of one run with the same task set
//! play the same boards.
//!
//! ```
//! use seads_games::Split;
//! use seads_planner::{EVALUATION_SEEDS, EvaluationKind, TaskSet};
//!
//! // The paper's protocol: 20 test boards per depth 1–5, the authors' 20 seeds.
//! let tasks = TaskSet::standard(20);
//! assert_eq!(tasks.seeds(), EVALUATION_SEEDS.to_vec());
//! // More boards keep the authors' 20 first.
//! assert_eq!(TaskSet::standard(30).seeds()[..20], EVALUATION_SEEDS[..]);
//! // The files of an evaluation of the last checkpoint with re-planning:
//! let kind = EvaluationKind::Replan;
//! assert_eq!(kind.results_file(&tasks.depths, None), "evaluation-replan.json");
//! assert_eq!(kind.tasks_file(&[6, 7, 8], Some(500)), "evaluation-replan-depths-6-8-epoch-000500-tasks.jsonl");
//! assert_eq!(tasks.split, Split::Test);
//! ```

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{BoardState, EnvConfig, EnvError};
use seads_games::{GameKind, Split, SymbolicState};

use crate::{PlanChoice, Search};
use serde::{Deserialize, Serialize};

/// The 20 environment seeds of the authors' evaluation jobs (the first 20 draws of
/// `randint(0, 10^8)` from NumPy's `RandomState(4343)`). They select other boards here than in
/// the reference (different RNG), but they fix the task list of this implementation.
pub const EVALUATION_SEEDS: [u64; 20] = [
    71503910, 12648915, 30568854, 4573881, 45446760, 94593131, 49877556, 8409767, 80251918,
    3111044, 91239881, 76542445, 17493797, 60709534, 18799053, 83516419, 64932163, 31287836,
    49353701, 42153732,
];

/// The seed of the stream that task seeds beyond the authors' 20 are drawn from.
pub const TASK_STREAM_SEED: u64 = 4343;

/// The paper's solution depths.
pub const STANDARD_DEPTHS: [usize; 5] = [1, 2, 3, 4, 5];

/// Boards per solution depth of the standard protocol: the authors' 20 seeds.
pub const STANDARD_BOARDS: usize = EVALUATION_SEEDS.len();

/// The tasks of an evaluation: `boards` boards of each solution depth from `split`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskSet {
    /// Solution depths of the boards.
    pub depths: Vec<usize>,
    /// Boards (environment seeds) per depth.
    pub boards: usize,
    /// The board split.
    pub split: Split,
    /// `None`: the authors' 20 seeds first, then draws from [`TASK_STREAM_SEED`]'s stream.
    /// `Some(s)`: every seed drawn from `s`'s stream.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl TaskSet {
    /// The paper's protocol with `boards` boards per depth: depths 1–5, test boards, the
    /// authors' seeds first.
    pub fn standard(boards: usize) -> Self {
        Self {
            depths: STANDARD_DEPTHS.to_vec(),
            boards,
            split: Split::Test,
            seed: None,
        }
    }

    /// The most tasks one evaluation may have: at well under a second each, more would run for
    /// weeks, and their seeds and results must fit into memory.
    pub const MAX_TASKS: usize = 1_000_000;

    /// Why this task set cannot be evaluated (no board, no depth, or more than
    /// [`MAX_TASKS`](Self::MAX_TASKS) tasks), or `None`.
    pub fn problem(&self) -> Option<String> {
        if self.boards == 0 || self.depths.is_empty() {
            return Some("an evaluation needs at least 1 board and 1 depth".into());
        }
        match self.depths.len().checked_mul(self.boards) {
            Some(n) if n <= Self::MAX_TASKS => None,
            _ => Some(format!(
                "{} boards at each of {} depth(s) are more than the {} tasks one evaluation may have",
                self.boards,
                self.depths.len(),
                Self::MAX_TASKS
            )),
        }
    }

    /// The environment seeds of the tasks, the same for every depth: one board per seed and
    /// depth.
    pub fn seeds(&self) -> Vec<u64> {
        let authors = match self.seed {
            None => &EVALUATION_SEEDS[..self.boards.min(EVALUATION_SEEDS.len())],
            Some(_) => &[],
        };
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed.unwrap_or(TASK_STREAM_SEED));
        let drawn = (authors.len()..self.boards).map(|_| rng.random_range(0..100_000_000));
        authors.iter().copied().chain(drawn).collect()
    }

    /// The board of the task of `depth` and `seed` on a `game` of `size`: the board that an
    /// environment seeded with `seed` draws at reset (for manipulators whose boards are set,
    /// such as the robot's twin).
    pub fn board(
        &self,
        game: GameKind,
        size: usize,
        depth: usize,
        seed: u64,
    ) -> Result<SymbolicState, EnvError> {
        let config = EnvConfig {
            reset_split: self.split,
            max_solution_depth: depth,
            random_solution_depth: false,
            ..EnvConfig::default()
        };
        let mut board = BoardState::new(game, size, &config)?;
        board.seed(seed);
        board.reset()?;
        Ok(board.board())
    }

    /// The number of tasks.
    pub fn len(&self) -> usize {
        self.depths.len() * self.boards
    }

    /// No task at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// States a search may expand by default: 2²² = 4,194,304. A learned model as good as the true
/// rules finds every 5×5 LightsOut board of depth ≤ 10 within it (3,850,756 boards lie at depth
/// ≤ 9), and a search stopped by it stops at the same state on every machine, loaded or not.
pub const DEFAULT_MAX_EXPANDED: usize = 1 << 22;

/// The limits of each search of an evaluation, and which plan it returns. By default a search is bounded by expanded
/// states only ([`DEFAULT_MAX_EXPANDED`]), so that an evaluation's outcome never depends on the
/// machine's speed or load; a wall-clock limit is an option.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SearchLimits {
    /// Seconds per search (`None`: no clock). A clock makes results depend on the machine.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timeout_s: Option<f64>,
    /// States expanded per search (`None`: no bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_expanded: Option<usize>,
    /// Which plan a search returns (records from before the choice: the first found).
    #[serde(default = "PlanChoice::paper")]
    pub plan: PlanChoice,
    /// How each search goes (records without it: breadth-first).
    #[serde(default, skip_serializing_if = "Search::is_breadth")]
    pub search: Search,
    /// Memory of each search's structures, MiB (`None`: the planner's default, 4 GiB; the
    /// paper's deeper search stopped at about 16 GB).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory_limit_mib: Option<usize>,
}

impl Default for SearchLimits {
    fn default() -> Self {
        Self {
            timeout_s: None,
            max_expanded: Some(DEFAULT_MAX_EXPANDED),
            plan: PlanChoice::MostLikely,
            search: Search::Breadth,
            memory_limit_mib: None,
        }
    }
}

impl SearchLimits {
    /// The planner's configuration for one search under these limits (the planner's other
    /// settings at their defaults).
    pub fn planner(&self) -> crate::PlannerConfig {
        crate::PlannerConfig {
            timeout_s: self.timeout_s,
            max_expanded: self.max_expanded,
            plan: self.plan,
            search: self.search,
            memory_limit_mib: self
                .memory_limit_mib
                .unwrap_or(crate::PlannerConfig::default().memory_limit_mib),
            ..crate::PlannerConfig::default()
        }
    }

    /// The limits in words: "4194304 expanded states", "60 s", "60 s or 20000 expanded states".
    pub fn describe(&self) -> String {
        match (self.timeout_s, self.max_expanded) {
            (Some(t), Some(m)) => format!("{t} s or {m} expanded states"),
            (Some(t), None) => format!("{t} s"),
            (None, Some(m)) => format!("{m} expanded states"),
            (None, None) => "no limit".to_owned(),
        }
    }
}

/// How an evaluation acts, as its files name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EvaluationKind {
    /// Plan, and plan again after every skill that deviated from the forward model.
    Replan,
    /// Plan once and execute the whole plan.
    PlanOnce,
    /// A baseline's policy acting alone, no planning.
    Policy,
}

impl EvaluationKind {
    /// The planning evaluation, with or without re-planning.
    pub fn planning(replan: bool) -> Self {
        if replan { Self::Replan } else { Self::PlanOnce }
    }

    /// The kind's name in file names.
    pub fn name(self) -> &'static str {
        match self {
            Self::Replan => "replan",
            Self::PlanOnce => "plan-once",
            Self::Policy => "policy",
        }
    }

    /// The stem of an evaluation's files: `evaluation-replan` for the standard depths 1–5 of
    /// the last checkpoint, which plots and reports read; `-depths-6-12` for another range,
    /// `-depths-1_3_5` for a list with gaps (a list never takes the name of its range), and
    /// `-epoch-000500` for a chosen checkpoint (`epoch`).
    pub fn stem(self, depths: &[usize], epoch: Option<u64>) -> String {
        let contiguous = depths.windows(2).all(|w| w[1] == w[0] + 1);
        let mut stem = format!("evaluation-{}", self.name());
        match (depths.first(), depths.last()) {
            _ if depths == STANDARD_DEPTHS => {}
            (Some(a), Some(b)) if contiguous => stem += &format!("-depths-{a}-{b}"),
            _ => {
                let list: Vec<String> = depths.iter().map(usize::to_string).collect();
                stem += &format!("-depths-{}", list.join("_"));
            }
        }
        if let Some(epoch) = epoch {
            stem += &format!("-epoch-{epoch:06}");
        }
        stem
    }

    /// The per-depth results ([`EvaluationRecord`](crate::EvaluationRecord), JSON).
    pub fn results_file(self, depths: &[usize], epoch: Option<u64>) -> String {
        format!("{}.json", self.stem(depths, epoch))
    }

    /// Every task, one JSON line each.
    pub fn tasks_file(self, depths: &[usize], epoch: Option<u64>) -> String {
        format!("{}-tasks.jsonl", self.stem(depths, epoch))
    }
}

/// Everything that decides an evaluation's outcome besides the agent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// How the agent acts.
    pub kind: EvaluationKind,
    /// Which boards.
    pub tasks: TaskSet,
    /// The search limits (`None` for a policy acting alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<SearchLimits>,
    /// Standard deviation of Gaussian noise on every low-level action
    /// ([`seads_embodiment::ActionNoise`]); `None`: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub action_noise: Option<f64>,
    /// Which forward model the planner searches with.
    #[serde(default, skip_serializing_if = "PlanModel::is_own")]
    pub model: PlanModel,
}

/// The forward model a planning evaluation searches with.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanModel {
    /// The one the agent learned while training (SEADS's).
    #[default]
    Own,
    /// One fitted afterwards to the agent's frozen skills (`seads fit-model`): the model any
    /// skill learner can be planned with, so that learners compare by their skills alone.
    Fitted,
}

impl PlanModel {
    /// Whether this is the agent's own model (the default, left out of the files).
    pub fn is_own(&self) -> bool {
        *self == Self::Own
    }
}

impl Protocol {
    /// A planning evaluation, with or without re-planning, on the standard tasks of depths 1–5
    /// with `boards` boards per depth, searches bounded by `limits` and no action noise.
    pub fn planning(replan: bool, boards: usize, limits: SearchLimits) -> Self {
        Self {
            kind: EvaluationKind::planning(replan),
            tasks: TaskSet::standard(boards),
            limits: Some(limits),
            action_noise: None,
            model: PlanModel::Own,
        }
    }

    /// How this protocol departs from the standard one: [`STANDARD_BOARDS`] test boards per
    /// depth with the authors' seeds and, for planning, searches under
    /// [`SearchLimits::default`] (2²² expanded states, no clock, the most likely plan,
    /// breadth-first, the planner's memory). One item per departure, as the files' names
    /// write it: `boards-2`, `train-boards`, `task-seed-7`, `expanded-1000` (or `unbounded`),
    /// `timeout-0.5s`, `first-found`, `both-ends`, `memory-16384mib`, `fitted-model`. Empty for
    /// the standard protocol.
    pub fn departures(&self) -> Vec<String> {
        let mut items = Vec::new();
        let tasks = &self.tasks;
        if tasks.boards != STANDARD_BOARDS {
            items.push(format!("boards-{}", tasks.boards));
        }
        if tasks.split != Split::Test {
            items.push("train-boards".to_owned());
        }
        if let Some(seed) = tasks.seed {
            items.push(format!("task-seed-{seed}"));
        }
        if let Some(limits) = &self.limits {
            let standard = SearchLimits::default();
            if limits.max_expanded != standard.max_expanded {
                items.push(match limits.max_expanded {
                    Some(states) => format!("expanded-{states}"),
                    None => "unbounded".to_owned(),
                });
            }
            if let Some(seconds) = limits.timeout_s {
                items.push(format!("timeout-{seconds}s"));
            }
            if limits.plan != standard.plan {
                items.push(limits.plan.name().to_owned());
            }
            if limits.search != standard.search {
                items.push(limits.search.name().to_owned());
            }
            if let Some(mib) = limits.memory_limit_mib {
                items.push(format!("memory-{mib}mib"));
            }
        }
        if self.model == PlanModel::Fitted {
            items.push("fitted-model".to_owned());
        }
        items
    }

    /// The protocol in a few words for tables and figures: `standard`, or its
    /// [departures](Self::departures) (`boards-2, expanded-1`).
    pub fn label(&self) -> String {
        let items = self.departures();
        if items.is_empty() {
            "standard".to_owned()
        } else {
            items.join(", ")
        }
    }

    /// The stem of this evaluation's files: the kind's ([`EvaluationKind::stem`]), then how the
    /// protocol departs from the standard one (`-boards-2-expanded-1`: [`departures`]), then
    /// `-noise-0.05` for an evaluation under action noise. Every part of the protocol is in the
    /// name, so an evaluation under other boards, limits or noise never takes the file of
    /// another; the standard protocol keeps the plain names that plots and reports read first.
    ///
    /// [`departures`]: Self::departures
    pub fn stem(&self, epoch: Option<u64>) -> String {
        let mut stem = self.kind.stem(&self.tasks.depths, None);
        for item in self.departures() {
            stem.push('-');
            stem += &item;
        }
        if let Some(std) = self.action_noise {
            stem += &format!("-noise-{std}");
        }
        if let Some(epoch) = epoch {
            stem += &format!("-epoch-{epoch:06}");
        }
        stem
    }

    /// The per-depth results ([`EvaluationRecord`](crate::EvaluationRecord), JSON).
    pub fn results_file(&self, epoch: Option<u64>) -> String {
        format!("{}.json", self.stem(epoch))
    }

    /// Every task, one JSON line each.
    pub fn tasks_file(&self, epoch: Option<u64>) -> String {
        format!("{}-tasks.jsonl", self.stem(epoch))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twenty_boards_or_fewer_are_the_authors_seeds_and_more_extend_them() {
        assert_eq!(TaskSet::standard(5).seeds(), EVALUATION_SEEDS[..5].to_vec());
        assert_eq!(TaskSet::standard(20).seeds(), EVALUATION_SEEDS.to_vec());
        let thirty = TaskSet::standard(30).seeds();
        assert_eq!(thirty.len(), 30);
        assert_eq!(thirty[..20], EVALUATION_SEEDS[..]);
        // The extension is a prefix of the stream: 40 boards extend 30.
        assert_eq!(TaskSet::standard(40).seeds()[..30], thirty[..]);
        let mut distinct = thirty.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), 30);
        // An explicit seed draws every seed from its stream.
        let own = TaskSet {
            seed: Some(7),
            ..TaskSet::standard(3)
        };
        assert_eq!(own.seeds().len(), 3);
        assert_ne!(own.seeds()[0], EVALUATION_SEEDS[0]);
        assert_eq!(own.seeds(), own.seeds());
    }

    #[test]
    fn a_task_board_is_the_board_an_environment_seeded_alike_draws() {
        let tasks = TaskSet::standard(3);
        for env_name in ["lightsout-cursor", "tileswap-reacher"] {
            for &depth in &[1, 4] {
                let config = EnvConfig {
                    reset_split: Split::Test,
                    max_solution_depth: depth,
                    random_solution_depth: false,
                    ..EnvConfig::default()
                };
                let mut env = seads_embodiment::make_env(env_name, &config).unwrap();
                let (game, size) = (env.spec().game, env.spec().board_size);
                for seed in tasks.seeds() {
                    env.seed(seed);
                    env.reset().unwrap();
                    assert_eq!(tasks.board(game, size, depth, seed).unwrap(), env.board());
                }
            }
        }
    }

    #[test]
    fn files_name_their_depths_and_a_chosen_checkpoint() {
        let replan = EvaluationKind::Replan;
        assert_eq!(replan.stem(&STANDARD_DEPTHS, None), "evaluation-replan");
        assert_eq!(
            EvaluationKind::PlanOnce.stem(&[6, 7, 8, 9, 10, 11, 12], None),
            "evaluation-plan-once-depths-6-12"
        );
        assert_eq!(
            EvaluationKind::Policy.stem(&[1, 2, 3], None),
            "evaluation-policy-depths-1-3"
        );
        assert_eq!(
            replan.stem(&[1, 3, 5], None),
            "evaluation-replan-depths-1_3_5",
            "a list with gaps must not overwrite the files of its range"
        );
        assert_eq!(replan.stem(&[7], None), "evaluation-replan-depths-7-7");
        assert_eq!(
            replan.results_file(&STANDARD_DEPTHS, Some(10)),
            "evaluation-replan-epoch-000010.json",
            "an earlier checkpoint must not take the file of the last"
        );
        assert_eq!(
            replan.tasks_file(&STANDARD_DEPTHS, None),
            "evaluation-replan-tasks.jsonl"
        );
    }

    /// Every part of a protocol that departs from the standard one is in its files' names, in
    /// one order, so that an evaluation under other boards or limits never takes the standard
    /// one's file (issue 82: `--max-expanded 1 --timeout 0.5` overwrote
    /// `evaluation-replan-depths-1-3.json`); the standard protocol keeps the plain names.
    #[test]
    fn files_name_every_departure_from_the_standard_protocol() {
        let standard = Protocol::planning(true, STANDARD_BOARDS, SearchLimits::default());
        assert_eq!(standard.results_file(None), "evaluation-replan.json");
        assert!(standard.departures().is_empty());
        assert_eq!(standard.label(), "standard");
        let limits = SearchLimits {
            max_expanded: Some(1),
            timeout_s: Some(0.5),
            ..SearchLimits::default()
        };
        let mut other = Protocol::planning(true, 5, limits);
        other.tasks.depths = vec![1, 2, 3];
        assert_eq!(
            other.results_file(None),
            "evaluation-replan-depths-1-3-boards-5-expanded-1-timeout-0.5s.json"
        );
        assert_eq!(other.label(), "boards-5, expanded-1, timeout-0.5s");
        let deep = Protocol::planning(
            false,
            STANDARD_BOARDS,
            SearchLimits {
                max_expanded: None,
                plan: PlanChoice::FirstFound,
                search: Search::BothEnds,
                memory_limit_mib: Some(16384),
                ..SearchLimits::default()
            },
        );
        assert_eq!(
            deep.tasks_file(Some(7)),
            "evaluation-plan-once-unbounded-first-found-both-ends-memory-16384mib-epoch-000007-tasks.jsonl"
        );
        let mut seeded = Protocol {
            action_noise: Some(0.05),
            ..Protocol::planning(true, STANDARD_BOARDS, SearchLimits::default())
        };
        seeded.tasks.seed = Some(7);
        seeded.tasks.split = Split::Train;
        assert_eq!(
            seeded.stem(None),
            "evaluation-replan-train-boards-task-seed-7-noise-0.05"
        );
        // A policy acting alone has no search limits: only its tasks can depart.
        let policy = Protocol {
            kind: EvaluationKind::Policy,
            tasks: TaskSet::standard(STANDARD_BOARDS),
            limits: None,
            action_noise: None,
            model: PlanModel::Own,
        };
        assert_eq!(policy.results_file(None), "evaluation-policy.json");
        // Planning with a model fitted afterwards is named as such, and only then.
        let fitted = Protocol {
            model: PlanModel::Fitted,
            ..Protocol::planning(false, STANDARD_BOARDS, SearchLimits::default())
        };
        assert_eq!(
            fitted.results_file(None),
            "evaluation-plan-once-fitted-model.json"
        );
        assert_eq!(fitted.label(), "fitted-model");
        let json = serde_json::to_string(&standard).unwrap();
        assert!(!json.contains("model"), "{json}");
        let back: Protocol =
            serde_json::from_str(&serde_json::to_string(&fitted).unwrap()).unwrap();
        assert_eq!(back, fitted);
        // Two protocols that differ anywhere have different files.
        let mut names = std::collections::BTreeSet::new();
        for boards in [1, 20] {
            for max_expanded in [None, Some(1), Some(DEFAULT_MAX_EXPANDED)] {
                for timeout_s in [None, Some(0.5)] {
                    for plan in [PlanChoice::MostLikely, PlanChoice::FirstFound] {
                        let limits = SearchLimits {
                            max_expanded,
                            timeout_s,
                            plan,
                            ..SearchLimits::default()
                        };
                        assert!(names.insert(Protocol::planning(true, boards, limits).stem(None)));
                    }
                }
            }
        }
    }

    /// Records name a search from both ends and a memory bound, and those from before either
    /// read as breadth-first search under the planner's default memory.
    #[test]
    fn limits_record_the_search_and_memory_and_old_records_read_as_breadth_first() {
        let old: SearchLimits =
            serde_json::from_str(r#"{"max_expanded":100,"plan":"most-likely"}"#).unwrap();
        assert_eq!(old.search, Search::Breadth);
        assert_eq!(old.memory_limit_mib, None);
        assert_eq!(old.planner().memory_limit_mib, 4096);
        let both = SearchLimits {
            search: Search::BothEnds,
            memory_limit_mib: Some(16 * 1024),
            ..old
        };
        let text = serde_json::to_string(&both).unwrap();
        assert!(text.contains(r#""search":"both-ends""#), "{text}");
        assert!(text.contains(r#""memory_limit_mib":16384"#), "{text}");
        assert_eq!(serde_json::from_str::<SearchLimits>(&text).unwrap(), both);
        assert_eq!(both.planner().search, Search::BothEnds);
        assert_eq!(both.planner().memory_limit_mib, 16384);
        assert!(!serde_json::to_string(&old).unwrap().contains("search"));
    }
}
