//! Breadth-first enumeration of every board by solution depth (SPEC §1.3).
//!
//! Boards are addressed by a dense index (LightsOut N ≤ 5: the board bits themselves; TileSwap:
//! the permutation's Lehmer rank), visited boards are tracked in a bitset, and each BFS layer is
//! kept as a list of indices in discovery order. LightsOut 5×5 thus needs a 4 MiB bitset plus
//! 4 bytes per board (≈ 36 MiB in all).

use crate::{BoardGame, GameError, MoveId, SymbolicState};

/// Largest index space [`enumerate`] accepts (indices are stored as `u32`).
const MAX_INDEX_SPACE: u64 = 1 << 32;

/// A game whose boards can be numbered densely, so that BFS can use a bitset.
pub trait Enumerable: BoardGame {
    /// Number of indices, or `None` when the state space does not fit a `u32` index.
    fn index_space(&self) -> Option<u64>;
    /// The index of a board.
    fn index_of(&self, board: SymbolicState) -> u32;
    /// The board with this index.
    fn board_at(&self, index: u32) -> SymbolicState;

    /// The indices of the boards one move away, by move id (`out.len() == num_moves()`).
    fn neighbours(&self, index: u32, out: &mut [u32]) {
        let board = self.board_at(index);
        for (mv, o) in out.iter_mut().enumerate() {
            *o = self.index_of(self.apply(board, mv));
        }
    }
}

/// All boards reachable from the goal, grouped by solution depth, in BFS discovery order.
#[derive(Debug, Clone)]
pub struct Enumeration {
    layers: Vec<Vec<u32>>,
}

impl Enumeration {
    /// Number of boards per depth; index = depth, entry 0 is the goal.
    pub fn depth_counts(&self) -> Vec<u64> {
        self.layers.iter().map(|l| l.len() as u64).collect()
    }

    /// Board indices of depth `d`, in discovery order (empty past the last layer).
    pub fn layer(&self, d: usize) -> &[u32] {
        self.layers.get(d).map_or(&[], Vec::as_slice)
    }

    /// The largest depth enumerated.
    pub fn max_depth(&self) -> usize {
        self.layers.len() - 1
    }

    /// Total number of boards enumerated.
    pub fn total(&self) -> u64 {
        self.layers.iter().map(|l| l.len() as u64).sum()
    }
}

/// Breadth-first search from the goal, up to `max_depth` moves (all reachable boards if `None`).
///
/// Every move can be undone by a move (LightsOut's and TileSwap's are their own inverses, a
/// slide is undone by sliding the tile back), so the layer in which a board first appears is its
/// solution depth. Errors if the game's state space is too large to index.
///
/// ```
/// use seads_games::{LightsOut, enumerate};
/// // 3×3 LightsOut's presses are independent: each set of k presses is its own board, at
/// // depth k, so the layers are the binomial coefficients C(9, k).
/// let all = enumerate(&LightsOut::new(3)?, None)?;
/// assert_eq!(all.depth_counts(), [1, 9, 36, 84, 126, 126, 84, 36, 9, 1]);
/// # Ok::<(), seads_games::GameError>(())
/// ```
pub fn enumerate<G: Enumerable + ?Sized>(
    game: &G,
    max_depth: Option<usize>,
) -> Result<Enumeration, GameError> {
    let space = game
        .index_space()
        .filter(|&s| s <= MAX_INDEX_SPACE)
        .ok_or_else(|| GameError::TooLargeToEnumerate {
            game: game.kind().name(),
            size: game.size(),
        })?;
    let mut visited = vec![0u64; space.div_ceil(64) as usize];
    let goal = game.index_of(game.goal());
    visited[(goal / 64) as usize] |= 1 << (goal % 64);
    let mut layers = vec![vec![goal]];
    let mut neighbours = vec![0u32; game.num_moves()];
    while max_depth.is_none_or(|m| layers.len() <= m) {
        let mut next = Vec::new();
        for &index in layers.last().expect("at least the goal layer") {
            game.neighbours(index, &mut neighbours);
            for &n in &neighbours {
                let (word, bit) = ((n / 64) as usize, 1u64 << (n % 64));
                if visited[word] & bit == 0 {
                    visited[word] |= bit;
                    next.push(n);
                }
            }
        }
        if next.is_empty() {
            break;
        }
        layers.push(next);
    }
    Ok(Enumeration { layers })
}

/// Solution depth of every board, indexed densely (one byte per index).
#[derive(Debug, Clone)]
pub struct DepthTable {
    depth: Vec<u8>,
}

impl DepthTable {
    /// Marks boards that are not reachable from the goal.
    const UNREACHABLE: u8 = u8::MAX;

    /// The complete depth table of a game (runs a full [`enumerate`]).
    pub fn build<G: Enumerable + ?Sized>(game: &G) -> Result<Self, GameError> {
        let e = enumerate(game, None)?;
        let space = game.index_space().expect("enumerate succeeded") as usize;
        let mut depth = vec![Self::UNREACHABLE; space];
        for d in 0..=e.max_depth() {
            for &i in e.layer(d) {
                depth[i as usize] = d as u8;
            }
        }
        Ok(Self { depth })
    }

    /// The solution depth of a board, `None` if it cannot reach the goal.
    pub fn depth<G: Enumerable + ?Sized>(&self, game: &G, board: SymbolicState) -> Option<u8> {
        let d = self.depth[game.index_of(board) as usize];
        (d != Self::UNREACHABLE).then_some(d)
    }

    /// An optimal move sequence to the goal (greedy descent through the depth table).
    pub fn solve<G: Enumerable + ?Sized>(
        &self,
        game: &G,
        board: SymbolicState,
    ) -> Result<Vec<MoveId>, GameError> {
        let unsolvable = || GameError::Unsolvable {
            game: game.kind().name(),
        };
        let mut d = self.depth(game, board).ok_or_else(unsolvable)?;
        let mut board = board;
        let mut moves = Vec::with_capacity(d as usize);
        while d > 0 {
            let mv = (0..game.num_moves())
                .find(|&m| self.depth(game, game.apply(board, m)) == Some(d - 1))
                .expect("a board of depth d > 0 has a neighbour of depth d - 1");
            board = game.apply(board, mv);
            moves.push(mv);
            d -= 1;
        }
        Ok(moves)
    }
}
