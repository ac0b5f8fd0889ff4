//! Breadth-first search over skill sequences on bit-packed symbolic states (SPEC §4.2).

use std::hash::Hash;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use rustc_hash::FxHashSet;
use seads_games::{Successor, SymbolicState};
use serde::{Deserialize, Serialize};

/// Which of the shortest plans a search returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlanChoice {
    /// The plan the forward model is surest of: among the plans that reach the goal in the batch
    /// where the goal was first generated, each step's skill the likeliest of those the model
    /// predicts to make that step, and of these plans the one with the highest product of the
    /// steps' probabilities. During re-planning, a skill that left another board than predicted
    /// is not chosen again from that board in the same task while another plan is left.
    #[default]
    MostLikely,
    /// The first plan found, in fringe-then-skill order (the reference's search).
    FirstFound,
    /// [`MostLikely`](Self::MostLikely), and wary of a skill that keeps failing: once a skill has
    /// left another board than predicted twice in a task, re-planning does not choose it again
    /// from any board while a plan without it is left (then as `MostLikely`). A learned skill
    /// that misses its move from one board mostly misses it from the next, whose board is new.
    MostLikelyWary,
}

impl std::str::FromStr for PlanChoice {
    type Err = String;

    /// `most-likely`, `first-found` or `most-likely-wary`, the names records use.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "most-likely" => Ok(Self::MostLikely),
            "first-found" => Ok(Self::FirstFound),
            "most-likely-wary" => Ok(Self::MostLikelyWary),
            other => Err(format!(
                "{other:?} is not one of most-likely, first-found, most-likely-wary"
            )),
        }
    }
}

impl PlanChoice {
    /// The name records and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Self::MostLikely => "most-likely",
            Self::FirstFound => "first-found",
            Self::MostLikelyWary => "most-likely-wary",
        }
    }

    /// The choice that evaluation records without one were made with.
    pub fn paper() -> Self {
        Self::FirstFound
    }
}

/// How a search goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Breadth-first from the start (the reference's search).
    #[default]
    Breadth,
    /// From both ends where the model's skills act as masks, every joined plan verified with
    /// the forward model ([`meet_plan`](crate::meet_plan)); breadth-first elsewhere.
    BothEnds,
}

impl std::str::FromStr for Search {
    type Err = String;

    /// `breadth` or `both-ends`, the names records use.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "breadth" => Ok(Self::Breadth),
            "both-ends" => Ok(Self::BothEnds),
            other => Err(format!("{other:?} is not one of breadth, both-ends")),
        }
    }
}

impl Search {
    /// The name records and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Breadth => "breadth",
            Self::BothEnds => "both-ends",
        }
    }

    /// Whether this is the default, breadth-first search (records leave it out).
    pub fn is_breadth(&self) -> bool {
        *self == Self::Breadth
    }
}

/// A flag that another thread raises to stop searches early (Ctrl-C in Python, whose signal
/// handlers run on the thread that waits for the search): a search that sees it raised ends with
/// [`PlanError::Interrupted`]. It is no part of a configuration's value: configurations that
/// differ only in it are equal, and it is never written.
#[derive(Debug, Clone, Default)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// A flag not raised.
    pub fn new() -> Self {
        Self::default()
    }

    /// Raises the flag: every search that holds it stops at its next check.
    pub fn raise(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether the flag was raised.
    pub fn is_raised(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// The flag itself, for a search outside this crate that checks one (the 15-puzzle's
    /// solver).
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }
}

impl PartialEq for Interrupt {
    /// Always: a stop handle is not part of what a configuration says.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Limits of one search. `Default` = the reference's 20 layers, a 4 GiB memory bound, no time
/// limit (the authors' evaluation used 60 s per search), the most likely plan.
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
    /// Which plan to return.
    pub plan: PlanChoice,
    /// How to search ([`find_plan`](crate::find_plan); [`bfs_plan`] is breadth-first whatever
    /// this says).
    pub search: Search,
    /// Raised by another thread to stop the search (never written).
    #[serde(skip)]
    pub interrupt: Interrupt,
}

impl PlannerConfig {
    /// What an evaluation whose searches have these limits keeps of the successors they
    /// computed ([`Memo`](crate::Memo)): half the search's memory bound, so that one memory
    /// option bounds both. By default 2 GiB, about 9.6 million states of 25 skills: on the
    /// twin's weakest agents, enough that a board met again in a later task is answered from
    /// memory (`docs/results/memo/`).
    pub fn memo_bytes(&self) -> usize {
        self.memory_limit_mib.saturating_mul(1 << 20) / 2
    }
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            max_layers: 20,
            memory_limit_mib: 4096,
            timeout_s: None,
            max_expanded: None,
            batch_size: 1024,
            plan: PlanChoice::MostLikely,
            search: Search::Breadth,
            interrupt: Interrupt::default(),
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
    /// The model's log-probability of the plan's predicted states (the sum of its steps'
    /// log q(z_{t+1} | z_t, k_t)), where the plan was chosen by it: [`PlanChoice::MostLikely`],
    /// a model with probabilities, and a choice to make (more than one way to the goal in the
    /// batch that found it, or more than one skill predicted to make a step).
    pub log_likelihood: Option<f32>,
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
    /// Another thread raised the search's [`Interrupt`].
    #[error("planning was interrupted")]
    Interrupted,
    /// The machine had no memory for the search's next states, below its own bound (an
    /// address-space limit, a full machine).
    #[error("planning stopped: no memory for more than {discovered} states")]
    OutOfMemory {
        /// Distinct states discovered.
        discovered: usize,
    },
}

/// A symbolic state packed into a hash key as small as the state allows.
trait Key: Copy + Eq + Hash + Send + Sync {
    fn pack(z: SymbolicState) -> Self;
    /// 64 well-mixed bits that pick the key's shard of the visited set. Not the hash the sets
    /// use (FxHash), so that the keys of one shard still spread over its buckets.
    fn spread(&self) -> u64;
}

/// Fibonacci hashing's multiplier: its product's high bits mix every input bit.
const SPREAD: u64 = 0x9e37_79b9_7f4a_7c15;

impl Key for u64 {
    fn pack(z: SymbolicState) -> Self {
        z.low_u64()
    }

    fn spread(&self) -> u64 {
        self.wrapping_mul(SPREAD)
    }
}

impl Key for u128 {
    fn pack(z: SymbolicState) -> Self {
        z.low_u128()
    }

    fn spread(&self) -> u64 {
        ((*self as u64) ^ ((*self >> 64) as u64).rotate_left(29)).wrapping_mul(SPREAD)
    }
}

impl Key for SymbolicState {
    fn pack(z: SymbolicState) -> Self {
        z
    }

    fn spread(&self) -> u64 {
        let [a, b, c, d] = self.words();
        (a ^ b.rotate_left(21) ^ c.rotate_left(42) ^ d.rotate_left(63)).wrapping_mul(SPREAD)
    }
}

/// The visited set, split into shards by key so that the shards take a batch's new states in
/// parallel; each shard sees its keys in batch order, so which occurrence of a state counts as
/// new is the same as with one set and one thread.
struct Visited<K> {
    shards: Vec<FxHashSet<K>>,
    len: usize,
}

/// log₂ of the number of shards.
const SHARD_BITS: u32 = 6;
/// Batches smaller than this are deduplicated on the calling thread.
const PARALLEL_MIN: usize = 1 << 14;

impl<K: Key> Visited<K> {
    fn new() -> Self {
        Self {
            shards: (0..1 << SHARD_BITS).map(|_| FxHashSet::default()).collect(),
            len: 0,
        }
    }

    fn shard(key: &K) -> usize {
        (key.spread() >> (64 - SHARD_BITS)) as usize
    }

    fn insert(&mut self, key: K) -> bool {
        let new = self.shards[Self::shard(&key)].insert(key);
        self.len += usize::from(new);
        new
    }

    /// Inserts `keys` in order and marks in `new` (same length, all false) the ones that were
    /// not there before: the first occurrence of each unseen key; returns how many. Uses the
    /// current rayon pool. Room for every key is made in its shard first, fallibly: a machine
    /// without the memory is an error and nothing is inserted, never an abort.
    fn insert_all(
        &mut self,
        keys: &[K],
        new: &mut [bool],
    ) -> Result<usize, std::collections::TryReserveError> {
        let before = self.len;
        if keys.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
            let mut counts = vec![0usize; self.shards.len()];
            for key in keys {
                counts[Self::shard(key)] += 1;
            }
            for (set, count) in self.shards.iter_mut().zip(counts) {
                set.try_reserve(count)?;
            }
            for (key, new) in keys.iter().zip(new.iter_mut()) {
                *new = self.insert(*key);
            }
            return Ok(self.len - before);
        }
        let shard_of: Vec<u8> = keys.par_iter().map(|k| Self::shard(k) as u8).collect();
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); self.shards.len()];
        for (i, &s) in shard_of.iter().enumerate() {
            members[usize::from(s)].push(i as u32);
        }
        for (set, members) in self.shards.iter_mut().zip(&members) {
            set.try_reserve(members.len())?;
        }
        let added: Vec<Vec<u32>> = self
            .shards
            .par_iter_mut()
            .zip(members.par_iter())
            .map(|(set, members)| {
                members
                    .iter()
                    .copied()
                    .filter(|&i| set.insert(keys[i as usize]))
                    .collect()
            })
            .collect();
        for i in added.iter().flatten() {
            new[*i as usize] = true;
        }
        self.len += added.iter().map(Vec::len).sum::<usize>();
        Ok(self.len - before)
    }

    /// Bytes the sets take, roughly (their capacity, a key and a control byte per slot).
    fn bytes(&self) -> usize {
        self.shards
            .iter()
            .map(|s| s.capacity() * (size_of::<K>() + 1))
            .sum()
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
///
/// The fringe is expanded in chunks of `config.batch_size` states, which are the unit of the
/// counts and limits (a plan's `expanded` counts whole chunks). Where the successor function
/// asks for larger batches ([`Successor::preferred_batch`], a GPU), several chunks are computed
/// in one call and then accounted chunk by chunk, so the plan and its counts do not change.
/// New states are deduplicated on the current rayon pool's threads; the result does not depend
/// on their number.
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
    let deadline = deadline(config, began);
    let k = successor.num_skills();
    let chunk_len = config.batch_size.max(1);
    let group_len = successor.preferred_batch().max(chunk_len);
    let limit_bytes = config.memory_limit_mib.saturating_mul(1 << 20);
    let mut nodes = vec![Node {
        state: start,
        parent: u32::MAX,
        skill: 0,
    }];
    let mut visited: Visited<K> = Visited::new();
    visited.insert(K::pack(start));
    let mut fringe = 0..1;
    let mut states = Vec::with_capacity(group_len);
    let mut out = Vec::with_capacity(group_len * k);
    let mut keys: Vec<K> = Vec::new();
    let mut new: Vec<bool> = Vec::new();
    let mut chunks = Vec::new();
    let mut expanded = 0;
    // The start's successors, kept from the first layer for the plan choice.
    let mut start_row: Vec<SymbolicState> = Vec::new();
    for _layer in 0..config.max_layers {
        let next_start = nodes.len();
        let mut chunk_start = fringe.start;
        while chunk_start < fringe.end {
            // The chunks of this group, cut exactly as one chunk per call would cut them (the
            // group may end up to a chunk past `group_len`).
            chunks.clear();
            let mut planned = expanded;
            let mut group_states = 0;
            while chunk_start < fringe.end && group_states < group_len {
                let budget = config
                    .max_expanded
                    .map_or(usize::MAX, |m| m.saturating_sub(planned));
                if budget == 0 {
                    break;
                }
                let len = chunk_len.min(budget);
                let chunk = chunk_start..(chunk_start + len).min(fringe.end);
                chunk_start = chunk.end;
                planned += chunk.len();
                group_states += chunk.len();
                chunks.push(chunk);
            }
            let (Some(first), Some(last)) = (chunks.first(), chunks.last()) else {
                return Err(PlanError::Budget { expanded });
            };
            let group = first.start..last.end;
            states.clear();
            states.extend(nodes[group.clone()].iter().map(|n| n.state));
            out.clear();
            successor.successors(&states, &mut out);
            if group.start == 0 {
                start_row.extend_from_slice(&out[..k]);
            }
            // Only the successors before the first goal count; the rest are never looked at.
            let found = out.par_iter().position_first(|&next| next == goal);
            let seen = found.unwrap_or(out.len());
            keys.clear();
            keys.par_extend(out[..seen].par_iter().map(|&z| K::pack(z)));
            new.clear();
            new.resize(seen, false);
            // The search's two growing structures take their room fallibly: a machine without
            // the memory ends the search with a reason.
            let out_of_memory = |nodes: &Vec<Node>| PlanError::OutOfMemory {
                discovered: nodes.len(),
            };
            let added = visited
                .insert_all(&keys, &mut new)
                .map_err(|_| out_of_memory(&nodes))?;
            nodes
                .try_reserve(added)
                .map_err(|_| out_of_memory(&nodes))?;
            for chunk in &chunks {
                expanded += chunk.len();
                for parent in chunk.clone() {
                    let row = (parent - group.start) * k;
                    for skill in 0..k {
                        if found == Some(row + skill) {
                            let first = trace(&nodes, parent, skill, goal, expanded, nodes.len());
                            if config.plan == PlanChoice::FirstFound {
                                return Ok(first);
                            }
                            // Every way to the goal from this chunk, in search order.
                            let hits: Vec<(usize, usize)> = chunk
                                .clone()
                                .flat_map(|p| (0..k).map(move |s| (p, s)))
                                .filter(|&(p, s)| out[(p - group.start) * k + s] == goal)
                                .take(MAX_CANDIDATES)
                                .collect();
                            let candidates: Vec<Plan> = hits
                                .iter()
                                .map(|&(p, s)| trace(&nodes, p, s, goal, expanded, nodes.len()))
                                .collect();
                            // The successors the search has computed of the start and of the
                            // states the candidates' last steps leave.
                            let rows = hits.iter().map(|&(p, _)| {
                                let row = (p - group.start) * k;
                                (nodes[p].state, &out[row..row + k])
                            });
                            let known: Vec<_> = std::iter::once((start, &start_row[..]))
                                .chain(rows)
                                .collect();
                            let chosen = most_likely(successor, start, candidates, &known);
                            return Ok(chosen.unwrap_or(first));
                        }
                        if new[row + skill] {
                            nodes.push(Node {
                                state: out[row + skill],
                                parent: parent as u32,
                                skill: skill as u16,
                            });
                        }
                    }
                }
                let used = nodes.capacity() * size_of::<Node>() + visited.bytes();
                if used > limit_bytes {
                    return Err(PlanError::MemoryLimit {
                        limit_mib: config.memory_limit_mib,
                        discovered: nodes.len(),
                    });
                }
                if deadline.is_some_and(|d| Instant::now() > d) {
                    return Err(PlanError::Timeout {
                        seconds: began.elapsed().as_secs_f64(),
                    });
                }
                if config.interrupt.is_raised() {
                    return Err(PlanError::Interrupted);
                }
            }
        }
        if nodes.len() == next_start {
            break;
        }
        fringe = next_start..nodes.len();
    }
    Err(PlanError::NotFound {
        layers: config.max_layers,
        discovered: visited.len,
    })
}

/// When a search begun at `began` must stop by the clock (`None`: never). Any number is a limit:
/// NaN and negative ones leave no time, and one too large for the clock (infinity included)
/// none at all.
pub(crate) fn deadline(config: &PlannerConfig, began: Instant) -> Option<Instant> {
    config.timeout_s.and_then(|s| {
        let limit = Duration::try_from_secs_f64(s.max(0.0)).ok()?;
        began.checked_add(limit)
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
        log_likelihood: None,
    }
}

/// Plans weighed against each other per goal: at most this many of a chunk's.
const MAX_CANDIDATES: usize = 64;

/// Of `candidates` (plans from `start`, in search order), the one the model is surest of, each
/// step's skill the likeliest of the skills whose predicted successor is that step's state; the
/// earliest of equals. `known` holds successor rows the caller has computed (a state and its K
/// successors); only the other steps' states are computed again. Where there is nothing to
/// choose (one candidate, and one skill predicted to make each of its steps), that candidate
/// comes back as it is, without asking the model for probabilities (its `log_likelihood` stays
/// `None`). `None` where the model has no probabilities or there is no candidate.
pub(crate) fn most_likely(
    successor: &mut dyn Successor,
    start: SymbolicState,
    mut candidates: Vec<Plan>,
    known: &[(SymbolicState, &[SymbolicState])],
) -> Option<Plan> {
    let k = successor.num_skills();
    // Each step as (from, to), every candidate's in turn.
    let steps: Vec<(SymbolicState, SymbolicState)> = candidates
        .iter()
        .flat_map(|plan| {
            std::iter::once(start)
                .chain(plan.predicted.iter().copied())
                .zip(plan.predicted.iter().copied())
        })
        .collect();
    // Each step's successor row: a known one, else computed here.
    let lookup = |z: SymbolicState| known.iter().find(|&&(y, _)| y == z).map(|&(_, row)| row);
    let missing: Vec<SymbolicState> = steps
        .iter()
        .map(|&(z, _)| z)
        .filter(|&z| lookup(z).is_none())
        .collect();
    let mut computed = Vec::with_capacity(missing.len() * k);
    successor.successors(&missing, &mut computed);
    let mut fresh = computed.chunks(k.max(1));
    let rows: Vec<&[SymbolicState]> = steps
        .iter()
        .map(|&(z, _)| lookup(z).or_else(|| fresh.next()).unwrap_or(&[]))
        .collect();
    // The skills predicted to make each step (the planned one does, so there is one).
    let makers: Vec<Vec<usize>> = steps
        .iter()
        .zip(&rows)
        .map(|(&(_, to), row)| (0..row.len()).filter(|&s| row[s] == to).collect())
        .collect();
    if candidates.len() == 1 && makers.iter().all(|m| m.len() == 1) {
        return candidates.pop();
    }
    // The probability of each step under each skill predicted to make it, step by step.
    let weighed: Vec<(SymbolicState, usize, SymbolicState)> = steps
        .iter()
        .zip(&makers)
        .flat_map(|(&(from, to), makers)| makers.iter().map(move |&s| (from, s, to)))
        .collect();
    let mut log_q = successor.log_likelihoods(&weighed)?.into_iter();
    let mut best: Option<Plan> = None;
    let mut offset = 0;
    for mut plan in candidates {
        let mut total = 0.0f32;
        for (t, skill) in plan.skills.iter_mut().enumerate() {
            let i = offset + t;
            // The likeliest skill that the model predicts to make this step; the lowest of
            // equals.
            let (chosen, ll) = makers[i]
                .iter()
                .map(|&s| (s, log_q.next().unwrap_or(f32::NAN)))
                // A NaN (a broken model) never wins.
                .map(|(s, ll)| (s, if ll.is_nan() { f32::NEG_INFINITY } else { ll }))
                .fold(None, |acc: Option<(usize, f32)>, (s, ll)| match acc {
                    Some((_, b)) if b >= ll => acc,
                    _ => Some((s, ll)),
                })?;
            *skill = chosen;
            total += ll;
        }
        offset += plan.skills.len();
        plan.log_likelihood = Some(total);
        if best
            .as_ref()
            .is_none_or(|b| b.log_likelihood.is_some_and(|b| total > b))
        {
            best = Some(plan);
        }
    }
    best
}
