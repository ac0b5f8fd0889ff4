//! Search from both ends: breadth-first from the start through the forward model, and from the
//! goal backwards through each skill's predicted effect, joined where the two meet and every
//! joined plan verified with the forward model.
//!
//! The backward half needs predecessors, which a forward model does not give. On LightsOut a
//! skill's predicted move rarely depends on the board, and a move flips the same fields on every
//! board, so a skill's effect is an exclusive-or mask: the board before `y` under skill `k` is
//! `y ^ effect[k]`. The search reads each skill's mask from the model (the most common change
//! over the first two layers' boards) and uses the backward half only where the masks explain
//! nearly every successor the model predicted there; elsewhere (TileSwap, whose swaps move
//! tiles rather than flip bits, or a model whose skills act by board) it is the plain
//! breadth-first search. A joined plan is a hypothesis until the forward model, run along its
//! backward half, reaches the goal; only then is it returned. So every plan is one the forward
//! model predicts to solve the board, as breadth-first search's are.
//!
//! Lengths: the sides grow a layer at a time (the cheap backward side one layer ahead), and the
//! joins are tried shortest first, so a plan is as short as breadth-first search's wherever the
//! masks hold along it. A plan whose backward half needs a skill acting against its mask is
//! found by the forward side alone, and may then be longer than breadth-first search's.

use std::ops::Range;
use std::time::Instant;

use rustc_hash::FxHashMap;
use seads_games::{Successor, SymbolicState};

use crate::bfs::{Plan, PlanChoice, PlanError, PlannerConfig, bfs_plan, most_likely};

/// Share of the first two layers' (board, skill) successors that the masks must explain for the
/// backward half to be used.
const MIN_AGREEMENT: f64 = 0.95;
/// Joins of one length verified at most (in search order); more are dropped.
const MAX_JOINS: usize = 4096;
/// Verified plans weighed against each other by [`PlanChoice::MostLikely`].
const MAX_CANDIDATES: usize = 64;

/// A board reached by one side: the index of the board it came from (the parent forward, the
/// child backward) and the skill between them.
#[derive(Clone, Copy)]
struct Node {
    state: SymbolicState,
    link: u32,
    skill: u16,
}

/// One side of the search: its boards in discovery order, layer by layer, and where each is.
struct Side {
    nodes: Vec<Node>,
    index: FxHashMap<SymbolicState, u32>,
    layers: Vec<Range<usize>>,
}

impl Side {
    fn new(root: SymbolicState) -> Self {
        let mut index = FxHashMap::default();
        index.insert(root, 0);
        Self {
            nodes: vec![Node {
                state: root,
                link: u32::MAX,
                skill: 0,
            }],
            index,
            layers: std::iter::once(0..1).collect(),
        }
    }

    /// Layers beyond the root.
    fn depth(&self) -> usize {
        self.layers.len() - 1
    }

    fn last(&self) -> Range<usize> {
        self.layers.last().expect("the root's layer").clone()
    }

    fn add(&mut self, state: SymbolicState, link: usize, skill: usize) {
        if let std::collections::hash_map::Entry::Vacant(slot) = self.index.entry(state) {
            slot.insert(self.nodes.len() as u32);
            self.nodes.push(Node {
                state,
                link: link as u32,
                skill: skill as u16,
            });
        }
    }

    fn layer_of(&self, node: usize) -> usize {
        self.layers.partition_point(|l| l.end <= node)
    }

    /// The skills from the root to `node` (forward) or from `node` to the root (backward), and
    /// the boards along them.
    fn path(&self, node: usize) -> (Vec<usize>, Vec<SymbolicState>) {
        let (mut skills, mut states) = (Vec::new(), Vec::new());
        let mut i = node;
        while self.nodes[i].link != u32::MAX {
            skills.push(usize::from(self.nodes[i].skill));
            states.push(self.nodes[i].state);
            i = self.nodes[i].link as usize;
        }
        (skills, states)
    }

    fn bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>()
            + self.index.capacity() * (size_of::<SymbolicState>() + size_of::<u32>() + 1)
    }
}

/// The search's running limits and counts.
struct Limits<'c> {
    config: &'c PlannerConfig,
    deadline: Option<Instant>,
    began: Instant,
    expanded: usize,
}

impl Limits<'_> {
    /// States that may still be expanded.
    fn budget(&self) -> usize {
        self.config
            .max_expanded
            .map_or(usize::MAX, |m| m.saturating_sub(self.expanded))
    }

    fn check(&self, sides: [&Side; 2]) -> Result<(), PlanError> {
        let used: usize = sides.iter().map(|s| s.bytes()).sum();
        if used > self.config.memory_limit_mib.saturating_mul(1 << 20) {
            return Err(PlanError::MemoryLimit {
                limit_mib: self.config.memory_limit_mib,
                discovered: sides.iter().map(|s| s.nodes.len()).sum(),
            });
        }
        if self.deadline.is_some_and(|d| Instant::now() > d) {
            return Err(PlanError::Timeout {
                seconds: self.began.elapsed().as_secs_f64(),
            });
        }
        if self.config.interrupt.is_raised() {
            return Err(PlanError::Interrupted);
        }
        Ok(())
    }
}

/// Plans from `start` to `goal` by searching from both ends where the model's skills act as
/// masks (see the module), breadth-first otherwise. The limits are `config`'s: states expanded
/// through `successor` (forward boards and verification steps), memory, clock, layers.
pub fn meet_plan(
    successor: &mut dyn Successor,
    start: SymbolicState,
    goal: SymbolicState,
    config: &PlannerConfig,
) -> Result<Plan, PlanError> {
    let began = Instant::now();
    let deadline = crate::bfs::deadline(config, began);
    let mut limits = Limits {
        config,
        deadline,
        began,
        expanded: 0,
    };
    let k = successor.num_skills();
    let mut forward = Side::new(start);
    let mut backward = Side::new(goal);
    // The masks, once the first two forward layers are expanded; the successors seen until then.
    let mut masks: Option<Vec<SymbolicState>> = None;
    let mut seen: Vec<(SymbolicState, SymbolicState)> = Vec::new();
    // Joins of every length not yet verified.
    let mut joins: std::collections::BTreeMap<usize, Vec<(usize, usize)>> = Default::default();
    loop {
        let cover = forward.depth() + backward.depth();
        if let Some((&length, _)) = joins.first_key_value()
            && length <= cover
        {
            let pairs = joins.remove(&length).expect("the first length");
            let plans = verify(successor, &forward, &backward, &pairs, goal, &mut limits)?;
            if let Some(plan) = choose(successor, start, plans, config.plan) {
                return Ok(Plan {
                    expanded: limits.expanded,
                    discovered: forward.nodes.len() + backward.nodes.len(),
                    ..plan
                });
            }
            continue;
        }
        if cover >= config.max_layers {
            break;
        }
        let grow_backward = masks.is_some() && backward.depth() <= forward.depth();
        let added = if grow_backward {
            grow_back(&mut backward, masks.as_deref().expect("masks"));
            backward.last()
        } else {
            let record = masks.is_none().then_some(&mut seen);
            grow_forward(successor, &mut forward, k, &mut limits, record)?;
            forward.last()
        };
        limits.check([&forward, &backward])?;
        if added.is_empty() && !grow_backward {
            // Every board the model reaches from the start is known, and none is the goal.
            break;
        }
        // The new layer's meetings with the other side.
        let (new, other) = if grow_backward {
            (&backward, &forward)
        } else {
            (&forward, &backward)
        };
        let depth = new.depth();
        for i in added {
            if let Some(&j) = other.index.get(&new.nodes[i].state) {
                let j = j as usize;
                let length = depth + other.layer_of(j);
                let pair = if grow_backward { (j, i) } else { (i, j) };
                joins.entry(length).or_default().push(pair);
            }
        }
        if masks.is_none() && forward.depth() == 2 {
            match read_masks(&seen, k) {
                Some(m) => masks = Some(m),
                None => return bfs_plan(successor, start, goal, config),
            }
        }
    }
    Err(PlanError::NotFound {
        layers: config.max_layers,
        discovered: forward.nodes.len() + backward.nodes.len(),
    })
}

/// Expands the forward side's last layer through the model, chunk by chunk; `record` keeps each
/// (board, successor) pair in (board, skill) order while the masks are unknown.
fn grow_forward(
    successor: &mut dyn Successor,
    side: &mut Side,
    k: usize,
    limits: &mut Limits,
    mut record: Option<&mut Vec<(SymbolicState, SymbolicState)>>,
) -> Result<(), PlanError> {
    let layer = side.last();
    let next = side.nodes.len();
    let chunk_len = limits.config.batch_size.max(1);
    let mut out = Vec::with_capacity(chunk_len * k);
    let mut chunk_start = layer.start;
    while chunk_start < layer.end {
        let len = chunk_len.min(limits.budget());
        if len == 0 {
            return Err(PlanError::Budget {
                expanded: limits.expanded,
            });
        }
        let chunk = chunk_start..(chunk_start + len).min(layer.end);
        chunk_start = chunk.end;
        let states: Vec<SymbolicState> =
            side.nodes[chunk.clone()].iter().map(|n| n.state).collect();
        out.clear();
        successor.successors(&states, &mut out);
        limits.expanded += chunk.len();
        for (row, parent) in chunk.enumerate() {
            for skill in 0..k {
                let to = out[row * k + skill];
                if let Some(seen) = record.as_deref_mut() {
                    seen.push((states[row], to));
                }
                side.add(to, parent, skill);
            }
        }
    }
    side.layers.push(next..side.nodes.len());
    Ok(())
}

/// Adds the backward side's next layer: the boards each skill's mask leads from to the last
/// layer's.
fn grow_back(side: &mut Side, masks: &[SymbolicState]) {
    let layer = side.last();
    let next = side.nodes.len();
    for child in layer {
        let state = side.nodes[child].state;
        for (skill, &mask) in masks.iter().enumerate() {
            side.add(state ^ mask, child, skill);
        }
    }
    side.layers.push(next..side.nodes.len());
}

/// Each skill's most common change over `seen` (pairs in (board, skill) order, `k` per board),
/// the lowest of equally common ones; `None` where the masks explain less than
/// [`MIN_AGREEMENT`] of the pairs.
fn read_masks(seen: &[(SymbolicState, SymbolicState)], k: usize) -> Option<Vec<SymbolicState>> {
    if seen.is_empty() {
        return None;
    }
    let mut agree = 0;
    let masks: Vec<SymbolicState> = (0..k)
        .map(|skill| {
            let mut counts: FxHashMap<SymbolicState, usize> = FxHashMap::default();
            for &(from, to) in seen.iter().skip(skill).step_by(k) {
                *counts.entry(from ^ to).or_default() += 1;
            }
            let (mask, n) = counts
                .into_iter()
                .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
                .expect("every skill has a pair");
            agree += n;
            mask
        })
        .collect();
    (agree as f64 >= MIN_AGREEMENT * seen.len() as f64).then_some(masks)
}

/// Runs the forward model along each join's backward half, all joins one step at a time, and
/// returns the plans that reach the goal, in join order.
fn verify(
    successor: &mut dyn Successor,
    forward: &Side,
    backward: &Side,
    pairs: &[(usize, usize)],
    goal: SymbolicState,
    limits: &mut Limits,
) -> Result<Vec<Plan>, PlanError> {
    let k = successor.num_skills();
    let pairs = &pairs[..pairs.len().min(MAX_JOINS)];
    // Each join as a plan in the making: the forward half's skills and boards, then the skills
    // of the backward half still to run.
    let mut plans: Vec<(Plan, Vec<usize>)> = pairs
        .iter()
        .map(|&(f, b)| {
            let (mut skills, mut predicted) = forward.path(f);
            skills.reverse();
            predicted.reverse();
            let (todo, _) = backward.path(b);
            let plan = Plan {
                skills,
                predicted,
                expanded: 0,
                discovered: 0,
                log_likelihood: None,
            };
            (plan, todo)
        })
        .collect();
    let start = forward.nodes[0].state;
    let mut out = Vec::new();
    for step in 0.. {
        let active: Vec<usize> = (0..plans.len())
            .filter(|&i| plans[i].1.len() > step)
            .collect();
        if active.is_empty() {
            break;
        }
        if limits.budget() < active.len() {
            return Err(PlanError::Budget {
                expanded: limits.expanded,
            });
        }
        let states: Vec<SymbolicState> = active
            .iter()
            .map(|&i| *plans[i].0.predicted.last().unwrap_or(&start))
            .collect();
        out.clear();
        successor.successors(&states, &mut out);
        limits.expanded += states.len();
        for (row, &i) in active.iter().enumerate() {
            let skill = plans[i].1[step];
            plans[i].0.skills.push(skill);
            plans[i].0.predicted.push(out[row * k + skill]);
        }
    }
    Ok(plans
        .into_iter()
        .map(|(plan, _)| plan)
        .filter(|plan| plan.predicted.last() == Some(&goal))
        .collect())
}

/// The plan `choice` takes of the verified `plans` (in search order).
fn choose(
    successor: &mut dyn Successor,
    start: SymbolicState,
    mut plans: Vec<Plan>,
    choice: PlanChoice,
) -> Option<Plan> {
    let first = plans.first()?.clone();
    match choice {
        PlanChoice::FirstFound => Some(first),
        PlanChoice::MostLikely | PlanChoice::MostLikelyWary => {
            plans.truncate(MAX_CANDIDATES);
            Some(most_likely(successor, start, plans, &[]).unwrap_or(first))
        }
    }
}
