//! LightsOut N×N (SPEC §1.1): pressing a field toggles it and its edge neighbours.

use std::sync::OnceLock;

use rand::RngExt;

use crate::{
    BoardGame, Enumerable, FieldMark, GameEntry, GameError, GameKind, Gf2Solver, MoveId, MoveSite,
    SymbolicState,
};

/// LightsOut in the registry.
pub(crate) static ENTRY: GameEntry = GameEntry {
    name: "lightsout",
    title: "LightsOut",
    description: "LightsOut N×N (3 to 13): a push toggles a field and its edge neighbours",
    default_size: 5,
    build: |size| Ok(Box::new(LightsOut::new(size)?)),
};

/// LightsOut on an N×N board, 3 ≤ N ≤ 13. Bit `row·N + col` of a board is 1 iff that light is on.
#[derive(Debug, Clone)]
pub struct LightsOut {
    n: usize,
    masks: Vec<SymbolicState>,
    /// The low 32 bits of every mask: the whole mask when N ≤ 5 (used by the enumeration).
    masks_low: Vec<u32>,
    /// The optimal solver, eliminated on first use.
    solver: OnceLock<Gf2Solver>,
}

impl LightsOut {
    /// Smallest supported side length.
    pub const MIN_SIZE: usize = 3;
    /// Largest supported side length (13×13 = 169 bits fit a [`SymbolicState`]).
    pub const MAX_SIZE: usize = 13;

    /// LightsOut on an `n`×`n` board.
    pub fn new(n: usize) -> Result<Self, GameError> {
        if !(Self::MIN_SIZE..=Self::MAX_SIZE).contains(&n) {
            return Err(GameError::UnsupportedSize {
                game: "lightsout",
                size: n,
                allowed: "3 to 13",
            });
        }
        let masks = (0..n * n)
            .map(|m| {
                let (r, c) = (m / n, m % n);
                let mut mask = SymbolicState::ZERO;
                mask.set(m, true);
                if r > 0 {
                    mask.set(m - n, true);
                }
                if r + 1 < n {
                    mask.set(m + n, true);
                }
                if c > 0 {
                    mask.set(m - 1, true);
                }
                if c + 1 < n {
                    mask.set(m + 1, true);
                }
                mask
            })
            .collect::<Vec<SymbolicState>>();
        let masks_low = masks.iter().map(|m| m.low_u64() as u32).collect();
        Ok(Self {
            n,
            masks,
            masks_low,
            solver: OnceLock::new(),
        })
    }

    /// The set of fields toggled by move `mv`.
    pub fn mask(&self, mv: MoveId) -> SymbolicState {
        self.masks[mv]
    }

    /// The GF(2) solver of this size, eliminated on first use.
    pub fn solver(&self) -> &Gf2Solver {
        self.solver.get_or_init(|| Gf2Solver::new(self))
    }

    /// The move masks as 32-bit words; complete only for N ≤ 5, where a board fits 25 bits.
    pub(crate) fn masks_low(&self) -> &[u32] {
        &self.masks_low
    }
}

/// For each byte, its eight bits as eight bytes 0 or 1 (bit i in byte i, little-endian).
const SPREAD: [u64; 256] = {
    let mut table = [0u64; 256];
    let mut byte = 0;
    while byte < 256 {
        let mut bit = 0;
        while bit < 8 {
            table[byte] |= ((byte as u64 >> bit) & 1) << (8 * bit);
            bit += 1;
        }
        byte += 1;
    }
    table
};

impl BoardGame for LightsOut {
    fn kind(&self) -> GameKind {
        GameKind::of(&ENTRY)
    }
    fn size(&self) -> usize {
        self.n
    }
    fn num_moves(&self) -> usize {
        self.n * self.n
    }
    fn symbolic_len(&self) -> usize {
        self.n * self.n
    }
    fn goal(&self) -> SymbolicState {
        SymbolicState::ZERO
    }
    #[inline]
    fn apply(&self, board: SymbolicState, mv: MoveId) -> SymbolicState {
        board ^ self.masks[mv]
    }
    fn values(&self, board: SymbolicState) -> Vec<u8> {
        (0..self.n * self.n).map(|d| board.get(d) as u8).collect()
    }
    /// Eight fields at a time: each byte of the board's bits spread over eight values.
    fn write_values(&self, board: SymbolicState, out: &mut [u8]) {
        let words = board.words();
        for (k, values) in out.chunks_mut(8).enumerate() {
            let byte = (words[k / 8] >> (8 * (k % 8))) & 0xff;
            values.copy_from_slice(&SPREAD[byte as usize].to_le_bytes()[..values.len()]);
        }
    }
    fn board_from_values(&self, values: &[u8]) -> Result<SymbolicState, GameError> {
        let expected = self.n * self.n;
        if values.len() != expected {
            return Err(GameError::WrongLength {
                game: "lightsout",
                expected,
                found: values.len(),
            });
        }
        let mut z = SymbolicState::ZERO;
        for (index, &v) in values.iter().enumerate() {
            match v {
                0 => {}
                1 => z.set(index, true),
                _ => {
                    return Err(GameError::BadSymbol {
                        game: "lightsout",
                        index,
                        symbol: v.to_string(),
                        allowed: "0 or 1",
                    });
                }
            }
        }
        Ok(z)
    }
    fn is_valid(&self, z: SymbolicState) -> bool {
        z.ones().all(|d| d < self.n * self.n)
    }
    fn allowed_values(&self) -> &'static str {
        "0 or 1"
    }
    fn move_site(&self, mv: MoveId) -> MoveSite {
        MoveSite::Field(mv)
    }
    fn field_mark(&self, value: u8) -> FieldMark {
        FieldMark::Light(value == 1)
    }
    fn describe_move(&self, mv: MoveId) -> String {
        format!("{mv} (press row {} col {})", mv / self.n, mv % self.n)
    }
    /// Every field on or off with probability ½ (a quarter of the 5×5 patterns are solvable).
    fn random_board(&self, rng: &mut dyn rand::Rng) -> SymbolicState {
        let mut z = SymbolicState::ZERO;
        for d in 0..self.n * self.n {
            z.set(d, rng.random::<bool>());
        }
        z
    }
    /// Up to 5×5 (2²⁵ boards).
    fn enumerable(&self) -> Option<&dyn Enumerable> {
        (self.n <= 5).then_some(self as &dyn Enumerable)
    }
    /// Lights flip, so `to` is reachable from `from` iff `from ⊕ to` is solvable (GF(2)).
    fn can_reach(&self, from: SymbolicState, to: SymbolicState) -> Option<bool> {
        Some(self.solver().depth(from ^ to).is_ok())
    }
    /// By linear algebra over GF(2) ([`Gf2Solver`]).
    fn solve(&self, board: SymbolicState) -> Option<Result<Vec<MoveId>, GameError>> {
        Some(self.solver().solve(board))
    }
    fn solution_depth(&self, board: SymbolicState) -> Option<Result<usize, GameError>> {
        Some(self.solver().depth(board))
    }
}

impl Gf2Solver {
    /// Eliminates the move matrix of `game`.
    pub fn new(game: &LightsOut) -> Self {
        Gf2Solver::from_masks(&game.masks)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::enumerate;

    #[test]
    fn corner_edge_interior_presses_toggle_3_4_5_fields() {
        let g = LightsOut::new(5).unwrap();
        assert_eq!(g.mask(0).ones().collect::<Vec<_>>(), vec![0, 1, 5]);
        assert_eq!(g.mask(2).count_ones(), 4);
        assert_eq!(
            g.mask(12).ones().collect::<Vec<_>>(),
            vec![7, 11, 12, 13, 17]
        );
        assert_eq!(g.mask(24).ones().collect::<Vec<_>>(), vec![19, 23, 24]);
    }

    #[test]
    fn sizes_outside_3_to_13_are_rejected() {
        for n in [2, 14] {
            assert!(matches!(
                LightsOut::new(n),
                Err(GameError::UnsupportedSize { .. })
            ));
        }
        assert_eq!(LightsOut::new(13).unwrap().num_moves(), 169);
    }

    #[test]
    fn parse_errors_name_the_problem() {
        let g = LightsOut::new(3).unwrap();
        assert_eq!(
            g.parse("1,0,1"),
            Err(GameError::WrongLength {
                game: "lightsout",
                expected: 9,
                found: 3
            })
        );
        assert!(matches!(
            g.parse("1,0,1,0,2,0,0,0,0"),
            Err(GameError::BadSymbol { index: 4, .. })
        ));
        assert!(matches!(
            g.parse("1,0,x,0,1,0,0,0,0"),
            Err(GameError::BadSymbol { index: 2, .. })
        ));
        let b = g.parse("1, 1,0,1,0,0,0,0,0").unwrap();
        assert_eq!(g.format(b), "1,1,0,1,0,0,0,0,0");
        assert_eq!(b, g.apply(g.goal(), 0));
    }

    #[test]
    fn five_by_five_has_rank_23_and_weight_12_quiet_patterns() {
        let s = Gf2Solver::new(&LightsOut::new(5).unwrap());
        assert_eq!(s.rank(), 23);
        assert_eq!(s.nullity(), 2);
        let g = LightsOut::new(5).unwrap();
        for &k in s.kernel() {
            let pressed: Vec<MoveId> = k.ones().collect();
            assert!(
                g.is_goal(g.apply_all(g.goal(), &pressed)),
                "quiet pattern changes nothing"
            );
            assert!(k.count_ones() >= 12);
        }
    }

    #[test]
    fn unsolvable_board_is_reported() {
        let g = LightsOut::new(5).unwrap();
        let s = Gf2Solver::new(&g);
        let mut board = g.goal();
        board.set(0, true); // a single lit corner is not in the image of A for 5×5
        assert_eq!(
            s.solve(board),
            Err(GameError::Unsolvable { game: "lightsout" })
        );
    }

    #[test]
    fn solves_known_board_optimally() {
        let g = LightsOut::new(5).unwrap();
        let s = Gf2Solver::new(&g);
        let board = g.apply_all(g.goal(), &[3, 7, 19]);
        assert_eq!(s.solve(board).unwrap(), vec![3, 7, 19]);
        assert_eq!(s.depth(g.goal()).unwrap(), 0);
    }

    #[test]
    fn thirteen_by_thirteen_is_invertible() {
        let g = LightsOut::new(13).unwrap();
        let s = Gf2Solver::new(&g);
        let board = g.apply_all(g.goal(), &[0, 84, 168]);
        let moves = s.solve(board).unwrap();
        assert!(g.is_goal(g.apply_all(board, &moves)));
        assert!(moves.len() <= 3);
    }

    #[test]
    fn small_lightsout_is_fully_solvable_at_3x3() {
        let e = enumerate(&LightsOut::new(3).unwrap(), None).unwrap();
        // The 3×3 move matrix is invertible: all 512 boards are solvable, depth counts C(9, d).
        assert_eq!(e.depth_counts(), vec![1, 9, 36, 84, 126, 126, 84, 36, 9, 1]);
    }

    #[test]
    fn large_lightsout_is_rejected() {
        assert!(matches!(
            enumerate(&LightsOut::new(6).unwrap(), None),
            Err(GameError::TooLargeToEnumerate { size: 6, .. })
        ));
    }
}
