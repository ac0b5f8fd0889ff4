//! Sampling boards of a given solution depth from a given split (SPEC §1.5).

use rand::seq::SliceRandom;
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
pub fn sample_by_action_sampling<R: Rng + ?Sized>(
    game: &dyn BoardGame,
    depth: usize,
    split: Split,
    rng: &mut R,
) -> SymbolicState {
    let mut moves: Vec<usize> = (0..game.num_moves()).collect();
    let depth = depth.min(moves.len());
    loop {
        moves.shuffle(rng);
        let board = game.apply_all(game.goal(), &moves[..depth]);
        if split_of(&game.values(board)) == split {
            return board;
        }
    }
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
            sample_by_action_sampling(&g, 5, Split::Train, &mut rng)
        };
        let b = draw(3);
        assert_eq!(split_of(&g.values(b)), Split::Train);
        assert!(b.count_ones() > 0);
        assert_eq!(draw(3), b);
    }
}
