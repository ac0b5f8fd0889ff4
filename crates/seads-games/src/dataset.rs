//! Sampling boards of a given solution depth from a given split (SPEC §1.5).

use itertools::Itertools as _;
use rand::seq::{IndexedRandom as _, SliceRandom};
use rand::{Rng, RngExt};

use crate::{BoardGame, Enumerable, GameError, Split, SymbolicState, enumerate, split_of};

/// The boards of depth 1..=max_depth, per split, in BFS discovery order (the reference's data set).
#[derive(Debug, Clone)]
pub struct BoardDataset {
    /// `boards[d][s]`: boards of depth d in split s (index 0 = train, 1 = test).
    boards: Vec<[Vec<SymbolicState>; 2]>,
}

impl BoardDataset {
    /// Enumerates the boards of `game` up to `max_depth` and splits them by CRC32.
    pub fn build<G: Enumerable + ?Sized>(game: &G, max_depth: usize) -> Result<Self, GameError> {
        let e = enumerate(game, Some(max_depth))?;
        let boards = (0..=e.max_depth())
            .map(|d| {
                let mut parts: [Vec<SymbolicState>; 2] = Default::default();
                for &i in e.layer(d) {
                    let board = game.board_at(i);
                    parts[split_index(split_of(&game.values(board)))].push(board);
                }
                parts
            })
            .collect();
        Ok(Self { boards })
    }

    /// The largest depth that has boards.
    pub fn max_depth(&self) -> usize {
        self.boards.len() - 1
    }

    /// The boards of depth `depth` in `split` (empty beyond the enumerated depths).
    pub fn boards(&self, depth: usize, split: Split) -> &[SymbolicState] {
        self.boards
            .get(depth)
            .map_or(&[], |parts| parts[split_index(split)].as_slice())
    }

    /// A board drawn uniformly among those of depth `depth` in `split`; `None` if there is none.
    ///
    /// ```
    /// use rand::SeedableRng;
    /// use seads_games::{BoardDataset, BoardGame, Gf2Solver, LightsOut, Split, split_of};
    /// let game = LightsOut::new(5)?;
    /// let data = BoardDataset::build(&game, 3)?;
    /// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    /// let board = data.sample(3, Split::Test, &mut rng).unwrap();
    /// assert_eq!(Gf2Solver::new(&game).depth(board)?, 3);
    /// assert_eq!(split_of(&game.values(board)), Split::Test);
    /// assert!(data.sample(4, Split::Test, &mut rng).is_none(), "built up to depth 3");
    /// # Ok::<(), seads_games::GameError>(())
    /// ```
    pub fn sample<R: Rng + ?Sized>(
        &self,
        depth: usize,
        split: Split,
        rng: &mut R,
    ) -> Option<SymbolicState> {
        let boards = self.boards(depth, split);
        (!boards.is_empty()).then(|| boards[rng.random_range(0..boards.len())])
    }
}

fn split_index(split: Split) -> usize {
    match split {
        Split::Train => 0,
        Split::Test => 1,
    }
}

/// A board made by `depth` distinct random moves from the goal, redrawn until it lies in `split`
/// (the reference's `reset_by_action_sampling`, used for boards too large to enumerate). The true
/// solution depth may be smaller than `depth`.
///
/// `None` where no such board lies in `split`: a depth that few move sets reach (at most
/// [`FEW_MOVE_SETS`]) may have none there, which [`action_sampling_boards`] tells beforehand. The
/// draws stop after [`MAX_DRAWS`]; then such a depth's boards are listed and one is drawn
/// among them.
pub fn sample_by_action_sampling<G: BoardGame + ?Sized, R: Rng + ?Sized>(
    game: &G,
    depth: usize,
    split: Split,
    rng: &mut R,
) -> Option<SymbolicState> {
    let mut moves: Vec<usize> = (0..game.num_moves()).collect();
    let depth = depth.min(moves.len());
    for _ in 0..MAX_DRAWS {
        moves.shuffle(rng);
        let board = game.apply_all(game.goal(), &moves[..depth]);
        if split_of(&game.values(board)) == split {
            return Some(board);
        }
    }
    action_sampling_boards(game, depth, split)?
        .choose(rng)
        .copied()
}

/// Draws of [`sample_by_action_sampling`] before it lists the boards instead.
pub const MAX_DRAWS: usize = 10_000;

/// The most move sets of one size that [`action_sampling_boards`] lists.
pub const FEW_MOVE_SETS: u128 = 4096;

/// The boards in `split` that `depth` distinct moves from the goal make, listed (distinct, in
/// move-set order) where there are at most [`FEW_MOVE_SETS`] such move sets; `None` where there
/// are more (then both splits hold many of them).
pub fn action_sampling_boards<G: BoardGame + ?Sized>(
    game: &G,
    depth: usize,
    split: Split,
) -> Option<Vec<SymbolicState>> {
    let n = game.num_moves();
    let depth = depth.min(n);
    // C(n, depth), stopped once it passes the limit.
    let mut sets: u128 = 1;
    for i in 0..depth.min(n - depth) {
        sets = sets * (n - i) as u128 / (i + 1) as u128;
        if sets > FEW_MOVE_SETS {
            return None;
        }
    }
    let mut boards: Vec<SymbolicState> = (0..n)
        .combinations(depth)
        .map(|moves| game.apply_all(game.goal(), &moves))
        .filter(|&board| split_of(&game.values(board)) == split)
        .collect();
    let mut seen = std::collections::BTreeSet::new();
    boards.retain(|&b| seen.insert(b));
    Some(boards)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LightsOut, TileSwap};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn depth_one_split_matches_paper() {
        let lo = BoardDataset::build(&LightsOut::new(5).unwrap(), 1).unwrap();
        assert_eq!(
            (
                lo.boards(1, Split::Train).len(),
                lo.boards(1, Split::Test).len()
            ),
            (7, 18)
        );
        let ts = BoardDataset::build(&TileSwap::new(), 1).unwrap();
        assert_eq!(
            (
                ts.boards(1, Split::Train).len(),
                ts.boards(1, Split::Test).len()
            ),
            (7, 5)
        );
    }

    #[test]
    fn samples_come_from_the_requested_depth_and_split() {
        let g = TileSwap::new();
        let data = BoardDataset::build(&g, 5).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..50 {
            let b = data.sample(4, Split::Test, &mut rng).unwrap();
            assert!(data.boards(4, Split::Test).contains(&b));
            assert_eq!(split_of(&g.values(b)), Split::Test);
        }
        assert_eq!(data.sample(9, Split::Test, &mut rng), None);
    }

    #[test]
    fn action_sampling_respects_split_and_seed() {
        let g = LightsOut::new(9).unwrap();
        let draw = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            sample_by_action_sampling(&g, 5, Split::Train, &mut rng).unwrap()
        };
        let b = draw(3);
        assert_eq!(split_of(&g.values(b)), Split::Train);
        assert!(b.count_ones() > 0);
        assert_eq!(draw(3), b);
    }

    /// 7×7 LightsOut has one board that all 49 moves make: the other split has no board of
    /// depth 49, which is said (`None`, an empty list) instead of drawn for ever; depth 48's 49
    /// boards are listed and split; depths that many move sets reach are not listed.
    #[test]
    fn a_depth_without_boards_in_a_split_is_said_not_drawn_for_ever() {
        let g = LightsOut::new(7).unwrap();
        let all = g.apply_all(g.goal(), &(0..49).collect::<Vec<_>>());
        let (has, lacks) = match split_of(&g.values(all)) {
            Split::Train => (Split::Train, Split::Test),
            Split::Test => (Split::Test, Split::Train),
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert_eq!(action_sampling_boards(&g, 49, has), Some(vec![all]));
        assert_eq!(action_sampling_boards(&g, 49, lacks), Some(Vec::new()));
        assert_eq!(sample_by_action_sampling(&g, 49, has, &mut rng), Some(all));
        assert_eq!(sample_by_action_sampling(&g, 49, lacks, &mut rng), None);
        let train = action_sampling_boards(&g, 48, Split::Train).unwrap();
        let test = action_sampling_boards(&g, 48, Split::Test).unwrap();
        assert_eq!(
            train.len() + test.len(),
            49,
            "49 distinct boards of 48 moves"
        );
        assert_eq!(
            action_sampling_boards(&g, 5, Split::Train),
            None,
            "C(49, 5) sets"
        );
    }
}
