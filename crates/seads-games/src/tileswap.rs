//! TileSwap 3×3 (SPEC §1.2): swap two edge-adjacent tiles; z is the 81-bit one-hot matrix.

use std::sync::OnceLock;

use rand::seq::SliceRandom;

use crate::perm::{FACTORIAL, rank, unrank};
use crate::{
    BoardGame, DepthTable, Enumerable, FieldMark, GameEntry, GameError, GameKind, MoveId, MoveSite,
    SymbolicState,
};

/// TileSwap in the registry.
pub(crate) static ENTRY: GameEntry = GameEntry {
    name: "tileswap",
    title: "TileSwap",
    description: "TileSwap 3×3: swap two edge-adjacent tiles",
    default_size: 3,
    build: |size| Ok(Box::new(TileSwap::with_size(size)?)),
};

/// Number of cells (and tiles) of the 3×3 board.
const CELLS: usize = 9;

/// The 12 swaps by move id (SPEC §1.2 table): ids 0–5 swap a cell with the cell below it,
/// ids 6–11 with the cell to its right.
const SWAPS: [(usize, usize); 12] = {
    let mut swaps = [(0, 0); 12];
    let mut id = 0;
    while id < 12 {
        swaps[id] = if id < 6 {
            let (r, c) = (id % 2, id / 2);
            (3 * r + c, 3 * (r + 1) + c)
        } else {
            let m = id - 6;
            let (r, c) = (m % 3, m / 3);
            (3 * r + c, 3 * r + c + 1)
        };
        id += 1;
    }
    swaps
};

/// TileSwap on the 3×3 board. A board holds a permutation of the tile ids 0..8; the goal has
/// tile `3r + c` at cell (r, c). Bit `9p + t` of z is 1 iff tile t lies in cell p.
#[derive(Debug, Clone, Default)]
pub struct TileSwap;

impl TileSwap {
    /// TileSwap 3×3.
    pub fn new() -> Self {
        TileSwap
    }

    /// TileSwap of side `n`; only 3 is defined (SPEC §1.2).
    pub fn with_size(n: usize) -> Result<Self, GameError> {
        if n == 3 {
            Ok(TileSwap)
        } else {
            Err(GameError::UnsupportedSize {
                game: "tileswap",
                size: n,
                allowed: "3",
            })
        }
    }

    /// The two row-major cells exchanged by move `mv`.
    pub fn swap_cells(mv: MoveId) -> (usize, usize) {
        SWAPS[mv]
    }

    /// The tiles per cell of a board given as its one-hot symbolic state.
    pub fn tiles(z: SymbolicState) -> [u8; CELLS] {
        let bits = z.low_u128();
        std::array::from_fn(|p| (((bits >> (9 * p)) & 0x1ff) as u16).trailing_zeros() as u8)
    }

    /// The one-hot symbolic state of a permutation (tile per cell).
    pub fn from_tiles(tiles: &[u8; CELLS]) -> SymbolicState {
        let bits = tiles
            .iter()
            .enumerate()
            .fold(0u128, |acc, (p, &t)| acc | 1u128 << (9 * p + t as usize));
        SymbolicState::from_u128(bits)
    }
}

impl BoardGame for TileSwap {
    fn kind(&self) -> GameKind {
        GameKind::of(&ENTRY)
    }
    fn size(&self) -> usize {
        3
    }
    fn num_moves(&self) -> usize {
        SWAPS.len()
    }
    fn symbolic_len(&self) -> usize {
        CELLS * CELLS
    }
    fn goal(&self) -> SymbolicState {
        Self::from_tiles(&[0, 1, 2, 3, 4, 5, 6, 7, 8])
    }
    #[inline]
    fn apply(&self, board: SymbolicState, mv: MoveId) -> SymbolicState {
        let (p, q) = SWAPS[mv];
        let bits = board.low_u128();
        let diff = ((bits >> (9 * p)) ^ (bits >> (9 * q))) & 0x1ff;
        SymbolicState::from_u128(bits ^ (diff << (9 * p)) ^ (diff << (9 * q)))
    }
    fn values(&self, board: SymbolicState) -> Vec<u8> {
        Self::tiles(board).to_vec()
    }
    fn write_values(&self, board: SymbolicState, out: &mut [u8]) {
        out.copy_from_slice(&Self::tiles(board));
    }
    fn board_from_values(&self, values: &[u8]) -> Result<SymbolicState, GameError> {
        if values.len() != CELLS {
            return Err(GameError::WrongLength {
                game: "tileswap",
                expected: CELLS,
                found: values.len(),
            });
        }
        let mut counts = [0usize; CELLS];
        for (index, &v) in values.iter().enumerate() {
            if v as usize >= CELLS {
                return Err(GameError::BadSymbol {
                    game: "tileswap",
                    index,
                    symbol: v.to_string(),
                    allowed: "a tile id 0..8",
                });
            }
            counts[v as usize] += 1;
        }
        if let Some(tile) = (0..CELLS).find(|&t| counts[t] != 1) {
            return Err(GameError::NotPermutation {
                game: "tileswap",
                last: 8,
                tile: tile as u8,
                count: counts[tile],
            });
        }
        let tiles: [u8; CELLS] = values.try_into().expect("length checked");
        Ok(Self::from_tiles(&tiles))
    }
    fn is_valid(&self, z: SymbolicState) -> bool {
        let bits = z.low_u128();
        if z.words()[2..].iter().any(|&w| w != 0) || bits >> 81 != 0 {
            return false;
        }
        let mut seen = 0u16;
        for p in 0..CELLS {
            let block = ((bits >> (9 * p)) & 0x1ff) as u16;
            if block.count_ones() != 1 {
                return false;
            }
            seen |= block;
        }
        seen == 0x1ff
    }
    fn allowed_values(&self) -> &'static str {
        "a tile id 0..8"
    }
    fn move_site(&self, mv: MoveId) -> MoveSite {
        let (p, q) = SWAPS[mv];
        MoveSite::Edge(p, q)
    }
    fn field_mark(&self, value: u8) -> FieldMark {
        FieldMark::Label(value.to_string())
    }
    fn describe_move(&self, mv: MoveId) -> String {
        let (p, q) = SWAPS[mv];
        format!("{mv} (swap ({},{})↔({},{}))", p / 3, p % 3, q / 3, q % 3)
    }
    /// Any permutation of the tiles (all 9! are reachable).
    fn random_board(&self, rng: &mut dyn rand::Rng) -> SymbolicState {
        let mut tiles: [u8; CELLS] = std::array::from_fn(|t| t as u8);
        tiles.shuffle(rng);
        Self::from_tiles(&tiles)
    }
    fn enumerable(&self) -> Option<&dyn Enumerable> {
        Some(self)
    }
    /// Through the complete depth table (9! boards, built on first use).
    fn solve(&self, board: SymbolicState) -> Option<Result<Vec<MoveId>, GameError>> {
        if !self.is_valid(board) {
            return Some(Err(GameError::Unsolvable { game: "tileswap" }));
        }
        Some(depth_table().solve(self, board))
    }
    fn solution_depth(&self, board: SymbolicState) -> Option<Result<usize, GameError>> {
        if !self.is_valid(board) {
            return Some(Err(GameError::Unsolvable { game: "tileswap" }));
        }
        Some(
            depth_table()
                .depth(self, board)
                .map(usize::from)
                .ok_or(GameError::Unsolvable { game: "tileswap" }),
        )
    }
}

/// TileSwap's complete depth table, shared by the process.
fn depth_table() -> &'static DepthTable {
    static TABLE: OnceLock<DepthTable> = OnceLock::new();
    TABLE.get_or_init(|| DepthTable::build(&TileSwap).expect("TileSwap 3×3 enumerates"))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::enumerate;

    #[test]
    fn move_table_matches_spec() {
        let expected = [
            (0, 3),
            (3, 6),
            (1, 4),
            (4, 7),
            (2, 5),
            (5, 8),
            (0, 1),
            (3, 4),
            (6, 7),
            (1, 2),
            (4, 5),
            (7, 8),
        ];
        assert_eq!(SWAPS, expected);
    }

    #[test]
    fn goal_is_identity_matrix() {
        let g = TileSwap::new();
        let z = g.goal();
        assert_eq!(
            z.ones().collect::<Vec<_>>(),
            (0..9).map(|p| 10 * p).collect::<Vec<_>>()
        );
        assert_eq!(g.format(z), "0,1,2,3,4,5,6,7,8");
        assert!(g.is_valid(z));
    }

    #[test]
    fn apply_swaps_tiles() {
        let g = TileSwap::new();
        let z = g.apply(g.goal(), 0);
        assert_eq!(TileSwap::tiles(z), [3, 1, 2, 0, 4, 5, 6, 7, 8]);
        let z = g.apply(g.goal(), 6);
        assert_eq!(g.format(z), "1,0,2,3,4,5,6,7,8");
    }

    #[test]
    fn parse_rejects_non_permutations() {
        let g = TileSwap::new();
        assert!(matches!(
            g.parse("0,1,2,3,4,5,6,7,7"),
            Err(GameError::NotPermutation {
                tile: 7,
                count: 2,
                ..
            })
        ));
        assert!(matches!(
            g.parse("0,1,2,3,4,5,6,7,9"),
            Err(GameError::BadSymbol { index: 8, .. })
        ));
        assert!(matches!(
            g.parse("0,1,2"),
            Err(GameError::WrongLength {
                expected: 9,
                found: 3,
                ..
            })
        ));
        assert!(matches!(
            TileSwap::with_size(4),
            Err(GameError::UnsupportedSize { .. })
        ));
        assert!(!g.is_valid(SymbolicState::from_u64(3)));
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
    fn depth_limit_stops_early() {
        let e = enumerate(&TileSwap::new(), Some(2)).unwrap();
        assert_eq!(e.depth_counts(), vec![1, 12, 88]);
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
