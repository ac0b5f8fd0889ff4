//! A successor function that remembers the successors another one computed, so that the
//! searches of one evaluation compute each state's successors once.
//!
//! Re-planning searches again from boards near the last one, and a search that avoids a failed
//! skill is followed by one that does not, and a board may come again in a later task: with a
//! forward model, many states are expanded again, and a task whose agent lacks a move spends
//! nearly all its time computing successors. The successor function is a function of the state, so remembering
//! it changes no plan; the states not remembered are computed in one call, in their order.

use rustc_hash::FxHashMap;
use seads_games::{Successor, SymbolicState};

/// Bytes a remembered state takes beyond its K successors (its key and row in the index, with
/// the index's spare capacity).
const ENTRY_OVERHEAD: usize = 24;

/// `inner` with a bounded memory of the successors it computed. States of at most 64 bits are
/// remembered (`u64` each); longer ones are passed through. The memory keeps the states used
/// most recently: it is two generations, each of half the capacity; a state found in the older
/// one moves to the younger, and when the younger is full it becomes the older and the older is
/// forgotten. What is remembered decides only how much is computed, never a successor.
pub struct Memo<'a> {
    inner: &'a mut dyn Successor,
    young: Generation,
    old: Generation,
    /// Most states a generation holds (0: nothing is remembered).
    half: usize,
    /// States answered from memory and computed.
    counts: (u64, u64),
    /// The current call's states computed (with their index among them), their successors,
    /// and every state's row (kept to reuse the space from call to call).
    missed: Vec<SymbolicState>,
    fresh: FxHashMap<u64, u32>,
    computed: Vec<SymbolicState>,
    rows: Vec<u64>,
}

/// Remembered states: each one's row of K successors, in pages of [`PAGE`] rows (a page is
/// allocated whole and never moved).
#[derive(Default)]
struct Generation {
    index: FxHashMap<u64, u32>,
    pages: Vec<Vec<u64>>,
}

/// Rows a page.
const PAGE: usize = 1 << 14;

impl Generation {
    fn row(&self, key: u64, k: usize) -> Option<&[u64]> {
        let row = *self.index.get(&key)? as usize;
        let at = (row % PAGE) * k;
        Some(&self.pages[row / PAGE][at..at + k])
    }

    fn len(&self) -> usize {
        self.index.len()
    }
}

impl<'a> Memo<'a> {
    /// `inner`, remembering successors in about `bytes` of memory (0: nothing).
    pub fn new(inner: &'a mut dyn Successor, bytes: usize) -> Self {
        let k = inner.num_skills().max(1);
        let capacity = if inner.symbolic_len() <= 64 {
            (bytes / (8 * k + ENTRY_OVERHEAD)).min(u32::MAX as usize)
        } else {
            0
        };
        Self {
            inner,
            young: Generation::default(),
            old: Generation::default(),
            half: capacity / 2,
            counts: (0, 0),
            missed: Vec::new(),
            fresh: FxHashMap::default(),
            computed: Vec::new(),
            rows: Vec::new(),
        }
    }

    /// States answered from memory and states computed so far.
    pub fn counts(&self) -> (u64, u64) {
        self.counts
    }

    /// Most states remembered at once (0 where states are longer than 64 bits).
    pub fn capacity(&self) -> usize {
        2 * self.half
    }

    /// Remembers `successors` of `key` in the younger generation, which first becomes the
    /// older one if it is full.
    fn remember(
        young: &mut Generation,
        old: &mut Generation,
        half: usize,
        key: u64,
        successors: &[u64],
    ) {
        if young.len() >= half {
            *old = std::mem::take(young);
        }
        let k = successors.len();
        if young.len().is_multiple_of(PAGE) {
            young.pages.push(Vec::with_capacity(PAGE * k));
        }
        young.index.insert(key, young.len() as u32);
        young
            .pages
            .last_mut()
            .expect("a page")
            .extend_from_slice(successors);
    }
}

impl Successor for Memo<'_> {
    fn num_skills(&self) -> usize {
        self.inner.num_skills()
    }

    fn symbolic_len(&self) -> usize {
        self.inner.symbolic_len()
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        let k = self.inner.num_skills();
        if self.half == 0 || k == 0 {
            self.inner.successors(states, out);
            return;
        }
        // Each state's row, from memory where it is there; the others computed in one call,
        // each once, in the order they first appear.
        let base = out.len();
        self.missed.clear();
        self.fresh.clear();
        let mut rows = std::mem::take(&mut self.rows);
        rows.clear();
        for z in states {
            let key = z.low_u64();
            match self.young.row(key, k).or_else(|| self.old.row(key, k)) {
                Some(found) => rows.extend_from_slice(found),
                None => {
                    let n = self.missed.len() as u32;
                    self.fresh.entry(key).or_insert_with(|| {
                        self.missed.push(*z);
                        n
                    });
                    rows.extend(std::iter::repeat_n(0, k)); // filled below
                }
            }
        }
        self.computed.clear();
        if !self.missed.is_empty() {
            self.inner.successors(&self.missed, &mut self.computed);
        }
        self.counts.0 += (states.len() - self.missed.len()) as u64;
        self.counts.1 += self.missed.len() as u64;
        for (z, row) in states.iter().zip(rows.chunks_mut(k)) {
            if let Some(&i) = self.fresh.get(&z.low_u64()) {
                let i = i as usize;
                for (r, s) in row.iter_mut().zip(&self.computed[i * k..(i + 1) * k]) {
                    *r = s.low_u64();
                }
            }
        }
        out.extend(rows.iter().map(|&s| SymbolicState::from_u64(s)));
        debug_assert_eq!(out.len() - base, states.len() * k);
        // The states of this call become the youngest remembered.
        for (z, row) in states.iter().zip(rows.chunks(k)) {
            let key = z.low_u64();
            if !self.young.index.contains_key(&key) {
                Self::remember(&mut self.young, &mut self.old, self.half, key, row);
            }
        }
        self.rows = rows;
    }

    fn preferred_batch(&self) -> usize {
        self.inner.preferred_batch()
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        self.inner.log_likelihoods(steps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use seads_games::{BoardGame, GameSuccessor, LightsOut};

    /// Counts the states it is asked for, and answers as the true game.
    struct Counted<'a> {
        game: GameSuccessor<'a>,
        asked: Vec<SymbolicState>,
    }

    impl Successor for Counted<'_> {
        fn num_skills(&self) -> usize {
            self.game.num_skills()
        }
        fn symbolic_len(&self) -> usize {
            self.game.symbolic_len()
        }
        fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
            self.asked.extend_from_slice(states);
            self.game.successors(states, out);
        }
    }

    #[test]
    fn a_state_is_computed_once_and_answered_alike() {
        let game = LightsOut::new(3).unwrap();
        let mut inner = Counted {
            game: GameSuccessor::new(&game),
            asked: Vec::new(),
        };
        let a = game.apply_all(game.goal(), &[1]);
        let b = game.apply_all(game.goal(), &[4, 8]);
        let mut truth = Vec::new();
        GameSuccessor::new(&game).successors(&[a, b, a, b], &mut truth);
        let mut memo = Memo::new(&mut inner, 1 << 20);
        let (mut first, mut second) = (Vec::new(), Vec::new());
        memo.successors(&[a, b, a], &mut first);
        memo.successors(&[b, a], &mut second);
        assert_eq!(first, truth[..27]);
        assert_eq!(second, truth[9..27]);
        assert_eq!(memo.counts(), (3, 2));
        drop(memo);
        assert_eq!(
            inner.asked,
            vec![a, b],
            "each state computed once, in order"
        );
    }

    #[test]
    fn the_memory_keeps_the_states_used_last_and_long_states_pass_through() {
        let game = LightsOut::new(3).unwrap();
        let mut inner = Counted {
            game: GameSuccessor::new(&game),
            asked: Vec::new(),
        };
        // Room for four states of 9 successors: two generations of two.
        let mut memo = Memo::new(&mut inner, 4 * (8 * 9 + ENTRY_OVERHEAD));
        assert_eq!(memo.capacity(), 4);
        let b: Vec<SymbolicState> = (0..4).map(|m| game.apply_all(game.goal(), &[m])).collect();
        let calls: [&[SymbolicState]; 6] = [
            &b[..2],  // young {0, 1}
            &b[2..3], // young {2}, old {0, 1}
            &b[..1],  // from the old generation: young {2, 0}
            &b[3..4], // young {3}, old {2, 0}: 1 is forgotten
            &b[1..2], // computed again
            &b[..1],  // remembered
        ];
        let mut out = Vec::new();
        for call in calls {
            memo.successors(call, &mut out);
        }
        let all: Vec<SymbolicState> = calls.concat();
        let mut truth = Vec::new();
        GameSuccessor::new(&game).successors(&all, &mut truth);
        assert_eq!(out, truth);
        assert_eq!(memo.counts(), (2, 5));
        drop(memo);
        assert_eq!(inner.asked, vec![b[0], b[1], b[2], b[3], b[1]]);

        let big = LightsOut::new(9).unwrap(); // 81 bits
        let mut inner = GameSuccessor::new(&big);
        assert_eq!(Memo::new(&mut inner, 1 << 30).capacity(), 0);
    }

    #[test]
    fn an_evaluation_remembers_half_its_searches_memory_bound() {
        let default = crate::PlannerConfig::default();
        assert_eq!(default.memo_bytes(), 2 << 30);
        let small = crate::PlannerConfig {
            memory_limit_mib: 1024,
            ..default
        };
        assert_eq!(small.memo_bytes(), 512 << 20);
        let huge = crate::PlannerConfig {
            memory_limit_mib: usize::MAX,
            ..crate::PlannerConfig::default()
        };
        assert_eq!(huge.memo_bytes(), usize::MAX / 2);
    }

    #[test]
    fn rows_over_several_pages_are_answered_alike() {
        let game = LightsOut::new(5).unwrap();
        let states: Vec<SymbolicState> = (0..2 * PAGE as u64 + 100)
            .map(|i| SymbolicState::from_u64(i.wrapping_mul(0x9e37_79b9) % (1 << 25)))
            .collect();
        let mut truth = Vec::new();
        GameSuccessor::new(&game).successors(&states, &mut truth);
        let mut inner = GameSuccessor::new(&game);
        let mut memo = Memo::new(&mut inner, 1 << 30);
        let (mut first, mut again) = (Vec::new(), Vec::new());
        for part in states.chunks(5000) {
            memo.successors(part, &mut first);
        }
        memo.successors(&states, &mut again);
        assert_eq!(first, truth);
        assert_eq!(again, truth);
        assert_eq!(memo.counts().1, states.len() as u64);
    }
}
