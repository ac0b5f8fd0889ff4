//! The board inside an environment: the game, its current state and the reset distribution.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardDataset, BoardGame, GameKind, MoveId, Split, SymbolicState};

use crate::{EnvConfig, EnvError};

/// Where reset boards come from.
#[derive(Clone)]
enum BoardSource {
    /// Uniform among the enumerated boards of a depth and split (LightsOut ≤ 5×5, TileSwap, the
    /// 8-puzzle).
    Dataset(Arc<BoardDataset>),
    /// Drawn by the game at a depth and split (games too large to enumerate; LightsOut: distinct
    /// random moves from the goal).
    Sampled,
}

/// The board side of an environment: the game, its current board, the reset distribution and
/// its own RNG stream (SPEC §1.5). Every environment of the registry holds one, and so does the
/// robot's; seeded with the same seed, each draws the same boards.
///
/// ```
/// use seads_embodiment::{BoardState, EnvConfig, make_env};
/// use seads_games::GameKind;
///
/// let config = EnvConfig { max_solution_depth: 3, random_solution_depth: false, ..EnvConfig::default() };
/// let mut board = BoardState::new(GameKind::named("lightsout")?, 5, &config)?;
/// board.seed(7);
/// board.reset()?;
/// // An environment seeded alike starts from the same board.
/// let mut env = make_env("lightsout-cursor", &config)?;
/// env.seed(7);
/// env.reset()?;
/// assert_eq!(env.board(), board.board());
/// # Ok::<(), seads_embodiment::EnvError>(())
/// ```
#[derive(Clone)]
pub struct BoardState {
    game: Arc<dyn BoardGame>,
    source: BoardSource,
    /// Depths up to the largest whose split holds no board, skipped when the depth is random.
    lacking: Vec<usize>,
    split: Split,
    max_depth: usize,
    random_depth: bool,
    board: SymbolicState,
    rng: ChaCha8Rng,
}

impl BoardState {
    /// A board of `kind` and `size` with the reset distribution of `config`.
    pub fn new(kind: GameKind, size: usize, config: &EnvConfig) -> Result<Self, EnvError> {
        let game: Arc<dyn BoardGame> = Arc::from(kind.build(size)?);
        let max_depth = config.max_solution_depth;
        let split = config.reset_split;
        let depths = if config.random_solution_depth {
            1..=max_depth
        } else {
            max_depth..=max_depth
        };
        let lacks = |d| {
            EnvError::InvalidConfig(format!(
                "{kind} {size}×{size} has no {split} boards of solution depth {d} (max_solution_depth = {max_depth})"
            ))
        };
        let (source, lacking) = if game.enumerable().is_some() {
            let data = dataset(kind, size, max_depth)?;
            let lacking: Vec<usize> = depths
                .clone()
                .filter(|&d| data.boards(d, split).is_empty())
                .collect();
            (BoardSource::Dataset(data), lacking)
        } else {
            // A depth that few move sets reach may have no board in the split (7×7 has one board
            // of depth 49): said now, not found by drawing for ever.
            let lacking = depths
                .clone()
                .filter(|&d| lacks_boards(game.as_ref(), d, split))
                .collect();
            (BoardSource::Sampled, lacking)
        };
        // A random depth skips the depths the split lacks (the 8-puzzle's two boards of depth 1
        // are both test boards); a fixed depth, or every depth, lacking is an error.
        if (lacking.len() == depths.clone().count() || !config.random_solution_depth)
            && let Some(&d) = lacking.first()
        {
            return Err(lacks(d));
        }
        let goal = game.goal();
        Ok(Self {
            game,
            source,
            lacking,
            split: config.reset_split,
            max_depth,
            random_depth: config.random_solution_depth,
            board: goal,
            rng: ChaCha8Rng::seed_from_u64(0),
        })
    }

    /// The game.
    pub fn game(&self) -> &dyn BoardGame {
        self.game.as_ref()
    }

    /// The current board.
    pub fn board(&self) -> SymbolicState {
        self.board
    }

    /// Restarts the board's RNG stream from `seed`.
    pub fn seed(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
    }

    /// The board's random stream, for an environment that draws the rest of its reset from it
    /// after the board (the robot's twin draws the pen's position there).
    pub fn rng(&mut self) -> &mut ChaCha8Rng {
        &mut self.rng
    }

    /// Draws a new board from the reset distribution. A game that draws its deep boards by a
    /// bounded search (the 15-puzzle) may find none of the depth asked for: an error that says
    /// so, and the board stays as it was.
    pub fn reset(&mut self) -> Result<(), EnvError> {
        let depth = if self.random_depth {
            loop {
                let depth = self.rng.random_range(1..=self.max_depth);
                if !self.lacking.contains(&depth) {
                    break depth;
                }
            }
        } else {
            self.max_depth
        };
        let drawn = match &self.source {
            BoardSource::Dataset(data) => data.sample(depth, self.split, &mut self.rng),
            BoardSource::Sampled => self.game.sample_at_depth(depth, self.split, &mut self.rng),
        };
        let game = self.game.kind();
        let size = self.game.size();
        self.board = drawn.ok_or_else(|| {
            EnvError::InvalidConfig(format!(
                "no {game} {size}×{size} board of solution depth {depth} in the {} split was \
                 found within the sampler's bound: choose a smaller max_solution_depth",
                self.split
            ))
        })?;
        Ok(())
    }

    /// Puts the board into `board` (for evaluation and replay).
    pub fn set(&mut self, board: SymbolicState) -> Result<(), EnvError> {
        if !self.game.is_valid(board) {
            return Err(EnvError::InvalidConfig(format!(
                "not a valid {} board: {board:?}",
                self.game.kind()
            )));
        }
        self.board = board;
        Ok(())
    }

    /// Makes move `mv`.
    pub fn apply(&mut self, mv: MoveId) {
        self.board = self.game.apply(self.board, mv);
    }
}

/// A cache of values built once per key and shared, for data every environment of a kind needs
/// (enumerated boards, depth maps): one per process, whatever the number of environments.
pub(crate) type Shared<K, V> = OnceLock<Mutex<BTreeMap<K, Arc<V>>>>;

/// The value of `key` in `cache`, built by `make` the first time.
pub(crate) fn shared<K: Ord, V>(cache: &Shared<K, V>, key: K, make: impl FnOnce() -> V) -> Arc<V> {
    let mut cache = cache
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    cache.entry(key).or_insert_with(|| Arc::new(make())).clone()
}

/// Whether `split` holds no board of `depth` for a game too large to enumerate
/// ([`BoardGame::lacks_boards`]), remembered per process: every environment of a vector asks it.
fn lacks_boards(game: &dyn BoardGame, depth: usize, split: Split) -> bool {
    static CACHE: Shared<(GameKind, usize, usize, bool), bool> = OnceLock::new();
    let key = (game.kind(), game.size(), depth, split == Split::Train);
    *shared(&CACHE, key, || game.lacks_boards(depth, split))
}

/// Enumerated boards are shared by every environment of the same game, size and depth.
fn dataset(kind: GameKind, size: usize, max_depth: usize) -> Result<Arc<BoardDataset>, EnvError> {
    static CACHE: Shared<(GameKind, usize, usize), BoardDataset> = OnceLock::new();
    let game = kind.build(size)?;
    if game.enumerable().is_none() {
        return Err(EnvError::InvalidConfig(format!(
            "{kind} {size}×{size} cannot be enumerated"
        )));
    }
    Ok(shared(&CACHE, (kind, size, max_depth), || {
        BoardDataset::build(game.enumerable().expect("checked"), max_depth)
            .expect("an enumerable game enumerates")
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use seads_games::{LightsOut, split_of};

    fn lightsout() -> GameKind {
        GameKind::named("lightsout").unwrap()
    }

    /// 7×7 LightsOut has one board of depth 49: an environment that would reset to depth 49 in
    /// the split that lacks it is refused when it is made (it used to draw for ever), and one in
    /// the split that has it resets to that board.
    #[test]
    fn a_depth_a_split_lacks_is_refused_when_the_board_is_made() {
        let game = LightsOut::new(7).unwrap();
        let all = game.apply_all(game.goal(), &(0..49).collect::<Vec<_>>());
        let has = split_of(&game.values(all));
        let lacks = match has {
            Split::Train => Split::Test,
            Split::Test => Split::Train,
        };
        let config = |split| EnvConfig {
            reset_split: split,
            max_solution_depth: 49,
            random_solution_depth: false,
            ..EnvConfig::default()
        };
        let refused = BoardState::new(lightsout(), 7, &config(lacks))
            .err()
            .unwrap();
        assert!(refused.to_string().contains("no"), "{refused}");
        assert!(refused.to_string().contains("depth 49"), "{refused}");
        let mut board = BoardState::new(lightsout(), 7, &config(has)).unwrap();
        board.seed(3);
        board.reset().unwrap();
        assert_eq!(board.board(), all);
    }
}
