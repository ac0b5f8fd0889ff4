//! Breadth-first enumeration of every board by solution depth (SPEC §1.3).
//!
//! Boards are addressed by a dense index (LightsOut N ≤ 5: the board bits themselves; TileSwap:
//! the permutation's Lehmer rank), visited boards are tracked in a bitset, and each BFS layer is
//! kept as a list of indices in discovery order. LightsOut 5×5 thus needs a 4 MiB bitset plus
//! 4 bytes per board (≈ 36 MiB in all).

use crate::{BoardGame, GameError, LightsOut, MoveId, SymbolicState, TileSwap};

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

impl Enumerable for LightsOut {
    fn index_space(&self) -> Option<u64> {
        let bits = self.num_moves() as u32;
        (bits <= 32).then(|| 1u64 << bits)
    }
    fn index_of(&self, board: SymbolicState) -> u32 {
        board.low_u64() as u32
    }
    fn board_at(&self, index: u32) -> SymbolicState {
        SymbolicState::from_u64(index as u64)
    }
    fn neighbours(&self, index: u32, out: &mut [u32]) {
        // The hot path of the 5×5 enumeration: one XOR per move.
        // `enumerate` only runs for N ≤ 5 (index_space), where the low 32 bits are the whole mask.
        for (o, m) in out.iter_mut().zip(self.masks_low()) {
            *o = index ^ m;
        }
    }
}

/// n! for n = 0..9.
const FACTORIAL: [u32; 10] = [1, 1, 2, 6, 24, 120, 720, 5040, 40320, 362880];

/// Lehmer rank of a permutation of 0..9 (lexicographic order, identity = 0).
fn rank(perm: &[u8; 9]) -> u32 {
    let mut used = 0u16;
    let mut r = 0;
    for (i, &p) in perm.iter().enumerate() {
        let smaller_used = (used & ((1u16 << p) - 1)).count_ones();
        r += (p as u32 - smaller_used) * FACTORIAL[8 - i];
        used |= 1 << p;
    }
    r
}

/// Inverse of [`rank`].
fn unrank(mut r: u32) -> [u8; 9] {
    let mut free: u16 = 0x1ff;
    std::array::from_fn(|i| {
        let f = FACTORIAL[8 - i];
        let mut k = r / f;
        r %= f;
        let mut bits = free;
        while k > 0 {
            bits &= bits - 1;
            k -= 1;
        }
        let p = bits.trailing_zeros() as u8;
        free &= !(1 << p);
        p
    })
}

impl Enumerable for TileSwap {
    fn index_space(&self) -> Option<u64> {
        Some(FACTORIAL[9] as u64)
    }
    fn index_of(&self, board: SymbolicState) -> u32 {
        rank(&TileSwap::tiles(board))
    }
    fn board_at(&self, index: u32) -> SymbolicState {
        TileSwap::from_tiles(&unrank(index))
    }
    fn neighbours(&self, index: u32, out: &mut [u32]) {
        // A swap of cells p < q only changes the Lehmer digits of positions p..=q, so each
        // neighbour's rank is the current rank plus the change of those few digits.
        let tiles = unrank(index);
        let mut suffix = [0u16; 9]; // suffix[i]: tiles at positions > i
        for i in (0..8).rev() {
            suffix[i] = suffix[i + 1] | 1 << tiles[i + 1];
        }
        let digit = |seen: u16, tile: u8| (seen & ((1u16 << tile) - 1)).count_ones() as i64;
        for (mv, o) in out.iter_mut().enumerate() {
            let (p, q) = TileSwap::swap_cells(mv);
            let (a, b) = (tiles[p], tiles[q]);
            let moved = (1u16 << a) | (1u16 << b);
            let mut delta = 0i64;
            for i in p..=q {
                let new_tile = if i == p {
                    b
                } else if i == q {
                    a
                } else {
                    tiles[i]
                };
                let new_suffix = if i < q { suffix[i] ^ moved } else { suffix[i] };
                delta += (digit(new_suffix, new_tile) - digit(suffix[i], tiles[i]))
                    * FACTORIAL[8 - i] as i64;
            }
            *o = (index as i64 + delta) as u32;
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
/// Moves are their own inverses, so the layer in which a board first appears is its solution
/// depth. Errors if the game's state space is too large to index.
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
            space: format!("2^{}", game.num_moves()),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rank_unrank_round_trip() {
        for r in [0, 1, 2, 100, 362879] {
            assert_eq!(rank(&unrank(r)), r);
        }
        assert_eq!(unrank(0), [0, 1, 2, 3, 4, 5, 6, 7, 8]);
        assert_eq!(unrank(362879), [8, 7, 6, 5, 4, 3, 2, 1, 0]);
    }

    #[test]
    fn incremental_tileswap_neighbours_match_full_ranking() {
        let g = TileSwap::new();
        let mut fast = [0u32; 12];
        for index in (0..362880).step_by(997) {
            g.neighbours(index, &mut fast);
            let board = g.board_at(index);
            for (mv, &n) in fast.iter().enumerate() {
                assert_eq!(n, g.index_of(g.apply(board, mv)), "rank {index}, move {mv}");
            }
        }
    }

    #[test]
    fn small_lightsout_is_fully_solvable_at_3x3() {
        let e = enumerate(&LightsOut::new(3).unwrap(), None).unwrap();
        // The 3×3 move matrix is invertible: all 512 boards are solvable, depth counts C(9, d).
        assert_eq!(e.depth_counts(), vec![1, 9, 36, 84, 126, 126, 84, 36, 9, 1]);
    }

    #[test]
    fn depth_limit_stops_early() {
        let e = enumerate(&TileSwap::new(), Some(2)).unwrap();
        assert_eq!(e.depth_counts(), vec![1, 12, 88]);
    }

    #[test]
    fn large_lightsout_is_rejected() {
        assert!(matches!(
            enumerate(&LightsOut::new(6).unwrap(), None),
            Err(GameError::TooLargeToEnumerate { size: 6, .. })
        ));
    }

    #[test]
    fn tileswap_solution_reaches_goal() {
        let g = TileSwap::new();
        let table = DepthTable::build(&g).unwrap();
        let board = g.parse("8,7,6,5,4,3,2,1,0").unwrap();
        let moves = table.solve(&g, board).unwrap();
        assert_eq!(moves.len() as u8, table.depth(&g, board).unwrap());
        assert!(g.is_goal(g.apply_all(board, &moves)));
    }
}
