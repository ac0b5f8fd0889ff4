//! Breadth-first search over skill sequences on bit-packed symbolic states (SPEC §4.2).

use std::hash::Hash;
use std::time::{Duration, Instant};

use rayon::prelude::*;
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
        let [a, b, c] = self.words();
        (a ^ b.rotate_left(21) ^ c.rotate_left(42)).wrapping_mul(SPREAD)
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
    /// not there before: the first occurrence of each unseen key. Uses the current rayon pool.
    fn insert_all(&mut self, keys: &[K], new: &mut [bool]) {
        if keys.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
            for (key, new) in keys.iter().zip(new.iter_mut()) {
                *new = self.insert(*key);
            }
            return;
        }
        let shard_of: Vec<u8> = keys.par_iter().map(|k| Self::shard(k) as u8).collect();
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); self.shards.len()];
        for (i, &s) in shard_of.iter().enumerate() {
            members[usize::from(s)].push(i as u32);
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
    // Any number is a limit: NaN and negative ones leave no time, and one too large for the
    // clock (infinity included) none at all.
    let deadline = config.timeout_s.and_then(|s| {
        let limit = Duration::try_from_secs_f64(s.max(0.0)).ok()?;
        began.checked_add(limit)
    });
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
            // Only the successors before the first goal count; the rest are never looked at.
            let found = out.par_iter().position_first(|&next| next == goal);
            let seen = found.unwrap_or(out.len());
            keys.clear();
            keys.par_extend(out[..seen].par_iter().map(|&z| K::pack(z)));
            new.clear();
            new.resize(seen, false);
            visited.insert_all(&keys, &mut new);
            for chunk in &chunks {
                expanded += chunk.len();
                for parent in chunk.clone() {
                    let row = (parent - group.start) * k;
                    for skill in 0..k {
                        if found == Some(row + skill) {
                            return Ok(trace(&nodes, parent, skill, goal, expanded, nodes.len()));
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
