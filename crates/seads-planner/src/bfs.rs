//! Breadth-first search over skill sequences on bit-packed symbolic states (SPEC §4.2).

use std::hash::Hash;
use std::time::{Duration, Instant};

use rustc_hash::FxHashSet;
use seads_games::{Successor, SymbolicState};
use serde::{Deserialize, Serialize};

/// Limits of one search. `Default` = the reference's 20 layers, a 4 GiB memory bound, no time
/// limit (the authors' evaluation used 60 s per search).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// Most layers (plan length) searched.
    pub max_layers: usize,
    /// Memory bound of the search structures, MiB.
    pub memory_limit_mib: usize,
    /// Wall-clock limit per search, seconds (`None`, or a value too large for the clock:
    /// unlimited; NaN or negative: none, the search stops at once).
    pub timeout_s: Option<f64>,
    /// Most states expanded per search (`None`: no bound). Unlike the clock, this limit stops
    /// every machine at the same state, so results under it are reproducible anywhere.
    pub max_expanded: Option<usize>,
    /// States expanded per call of the successor function.
    pub batch_size: usize,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            max_layers: 20,
            memory_limit_mib: 4096,
            timeout_s: None,
            max_expanded: None,
            batch_size: 1024,
        }
    }
}

/// A plan found by [`bfs_plan`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// The skills to execute, in order.
    pub skills: Vec<usize>,
    /// The symbolic state the model predicts after each skill (the last is the goal).
    pub predicted: Vec<SymbolicState>,
    /// States expanded (successor function evaluated for all skills).
    pub expanded: usize,
    /// Distinct states discovered.
    pub discovered: usize,
}

/// Why a search found no plan.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
pub enum PlanError {
    /// Every reachable state was expanded, or the layer limit was hit, without reaching the goal.
    #[error(
        "no plan: the goal was not reached within {layers} layers ({discovered} states discovered)"
    )]
    NotFound {
        /// Layers searched.
        layers: usize,
        /// Distinct states discovered.
        discovered: usize,
    },
    /// The search structures outgrew the memory bound.
    #[error("planning stopped at the memory bound of {limit_mib} MiB after {discovered} states")]
    MemoryLimit {
        /// The bound.
        limit_mib: usize,
        /// Distinct states discovered.
        discovered: usize,
    },
    /// The search ran out of time.
    #[error("planning stopped after {seconds:.1} s (time limit)")]
    Timeout {
        /// Seconds spent.
        seconds: f64,
    },
    /// The search expanded as many states as it may.
    #[error("planning stopped after expanding {expanded} states (state budget)")]
    Budget {
        /// States expanded.
        expanded: usize,
    },
}

/// A symbolic state packed into a hash key as small as the state allows.
trait Key: Copy + Eq + Hash {
    fn pack(z: SymbolicState) -> Self;
}

impl Key for u64 {
    fn pack(z: SymbolicState) -> Self {
        z.low_u64()
    }
}

impl Key for u128 {
    fn pack(z: SymbolicState) -> Self {
        z.low_u128()
    }
}

impl Key for SymbolicState {
    fn pack(z: SymbolicState) -> Self {
        z
    }
}

/// A discovered state: where it came from.
#[derive(Clone, Copy)]
struct Node {
    state: SymbolicState,
    parent: u32,
    skill: u16,
}

/// Breadth-first search from `start` to `goal` through `successor`, layer by layer; every state
/// of the fringe is expanded by every skill in order, and the goal test happens when a state is
/// generated (the first match in fringe-then-skill order wins), as in the reference. The start
/// itself is never tested (tasks have depth ≥ 1).
pub fn bfs_plan(
    successor: &mut dyn Successor,
    start: SymbolicState,
    goal: SymbolicState,
    config: &PlannerConfig,
) -> Result<Plan, PlanError> {
    match successor.symbolic_len() {
        0..=64 => search::<u64>(successor, start, goal, config),
        65..=128 => search::<u128>(successor, start, goal, config),
        _ => search::<SymbolicState>(successor, start, goal, config),
    }
}

fn search<K: Key>(
    successor: &mut dyn Successor,
    start: SymbolicState,
    goal: SymbolicState,
    config: &PlannerConfig,
) -> Result<Plan, PlanError> {
    let began = Instant::now();
    // Any number is a limit: NaN and negative ones leave no time, and one too large for the
    // clock (infinity included) none at all.
    let deadline = config.timeout_s.and_then(|s| {
        let limit = Duration::try_from_secs_f64(s.max(0.0)).ok()?;
        began.checked_add(limit)
    });
    let k = successor.num_skills();
    let limit_bytes = config.memory_limit_mib.saturating_mul(1 << 20);
    let mut nodes = vec![Node {
        state: start,
        parent: u32::MAX,
        skill: 0,
    }];
    let mut visited: FxHashSet<K> = FxHashSet::default();
    visited.insert(K::pack(start));
    let mut fringe = 0..1;
    let mut states = Vec::with_capacity(config.batch_size);
    let mut out = Vec::with_capacity(config.batch_size * k);
    let mut expanded = 0;
    for _layer in 0..config.max_layers {
        let next_start = nodes.len();
        let mut chunk_start = fringe.start;
        while chunk_start < fringe.end {
            let budget = config
                .max_expanded
                .map_or(usize::MAX, |m| m.saturating_sub(expanded));
            if budget == 0 {
                return Err(PlanError::Budget { expanded });
            }
            let len = config.batch_size.max(1).min(budget);
            let chunk = chunk_start..(chunk_start + len).min(fringe.end);
            chunk_start = chunk.end;
            states.clear();
            states.extend(nodes[chunk.clone()].iter().map(|n| n.state));
            out.clear();
            successor.successors(&states, &mut out);
            expanded += states.len();
            for (offset, parent) in chunk.enumerate() {
                for (skill, &next) in out[offset * k..(offset + 1) * k].iter().enumerate() {
                    if next == goal {
                        return Ok(trace(&nodes, parent, skill, goal, expanded, visited.len()));
                    }
                    if visited.insert(K::pack(next)) {
                        nodes.push(Node {
                            state: next,
                            parent: parent as u32,
                            skill: skill as u16,
                        });
                    }
                }
            }
            let used =
                nodes.capacity() * size_of::<Node>() + visited.capacity() * (size_of::<K>() + 1);
            if used > limit_bytes {
                return Err(PlanError::MemoryLimit {
                    limit_mib: config.memory_limit_mib,
                    discovered: visited.len(),
                });
            }
            if deadline.is_some_and(|d| Instant::now() > d) {
                return Err(PlanError::Timeout {
                    seconds: began.elapsed().as_secs_f64(),
                });
            }
        }
        if nodes.len() == next_start {
            break;
        }
        fringe = next_start..nodes.len();
    }
    Err(PlanError::NotFound {
        layers: config.max_layers,
        discovered: visited.len(),
    })
}

/// The skill sequence ending with `skill` applied to node `parent`, walked back to the root.
fn trace(
    nodes: &[Node],
    parent: usize,
    skill: usize,
    goal: SymbolicState,
    expanded: usize,
    discovered: usize,
) -> Plan {
    let mut skills = vec![skill];
    let mut predicted = vec![goal];
    let mut i = parent;
    while nodes[i].parent != u32::MAX {
        skills.push(nodes[i].skill as usize);
        predicted.push(nodes[i].state);
        i = nodes[i].parent as usize;
    }
    skills.reverse();
    predicted.reverse();
    Plan {
        skills,
        predicted,
        expanded,
        discovered,
    }
}
