//! Optimal LightsOut solutions by linear algebra over GF(2).
//!
//! Moves commute and are self-inverse, so a solution is a *set* of moves x with A·x = b, where
//! column m of A is the mask of move m. The shortest solution is the lightest x in the coset
//! x₀ + ker A; its weight is the board's solution depth (the BFS layer of SPEC §1.3).

use crate::{GameError, MoveId, SymbolicState};

/// A reusable solver for one LightsOut size: the elimination of A is done once, at construction.
#[derive(Debug, Clone)]
pub struct Gf2Solver {
    dim: usize,
    rank: usize,
    /// Row r of the reduced system is the XOR of the original equations in `transform[r]`.
    transform: Vec<SymbolicState>,
    /// Pivot column of reduced row r, for r < rank.
    pivots: Vec<usize>,
    /// A basis of the null space of A ("quiet patterns").
    kernel: Vec<SymbolicState>,
}

impl Gf2Solver {
    /// Eliminates the move matrix whose column m is `masks[m]`, the fields move m toggles
    /// (LightsOut's: [`Gf2Solver::new`]). The matrix must be symmetric, as LightsOut's is.
    pub(crate) fn from_masks(masks: &[SymbolicState]) -> Self {
        let dim = masks.len();
        // The equation of field i: Σ_m [move m toggles i]·x_m = b_i. A is symmetric, so the
        // coefficients of equation i are exactly the mask of move i.
        let mut rows: Vec<SymbolicState> = masks.to_vec();
        let mut transform: Vec<SymbolicState> = (0..dim)
            .map(|i| {
                let mut t = SymbolicState::ZERO;
                t.set(i, true);
                t
            })
            .collect();
        let mut pivots = Vec::new();
        for col in 0..dim {
            let r = pivots.len();
            let Some(p) = (r..dim).find(|&i| rows[i].get(col)) else {
                continue;
            };
            rows.swap(r, p);
            transform.swap(r, p);
            for i in 0..dim {
                if i != r && rows[i].get(col) {
                    let (row, t) = (rows[r], transform[r]);
                    rows[i] ^= row;
                    transform[i] ^= t;
                }
            }
            pivots.push(col);
        }
        let rank = pivots.len();
        let kernel = (0..dim)
            .filter(|c| !pivots.contains(c))
            .map(|free| {
                let mut v = SymbolicState::ZERO;
                v.set(free, true);
                for (r, &p) in pivots.iter().enumerate() {
                    if rows[r].get(free) {
                        v.set(p, true);
                    }
                }
                v
            })
            .collect();
        Self {
            dim,
            rank,
            transform,
            pivots,
            kernel,
        }
    }

    /// Rank of the move matrix (23 for 5×5, so 2^23 boards are solvable).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Dimension of the null space: every solvable board has 2^nullity solutions.
    pub fn nullity(&self) -> usize {
        self.dim - self.rank
    }

    /// The quiet patterns spanning the null space.
    pub fn kernel(&self) -> &[SymbolicState] {
        &self.kernel
    }

    /// Whether some set of moves turns `board` off.
    pub fn is_solvable(&self, board: SymbolicState) -> bool {
        (self.rank..self.dim).all(|r| !parity(self.transform[r] & board))
    }

    /// A shortest set of moves turning `board` off, as ascending move ids.
    ///
    /// ```
    /// use seads_games::{BoardGame, Gf2Solver, LightsOut};
    /// let game = LightsOut::new(5)?;
    /// let board = game.apply_all(game.goal(), &[7, 3, 18]);
    /// let solver = Gf2Solver::new(&game);
    /// // Presses commute and undo themselves: the same three, in order.
    /// assert_eq!(solver.solve(board)?, vec![3, 7, 18]);
    /// assert_eq!(solver.depth(board)?, 3);
    /// # Ok::<(), seads_games::GameError>(())
    /// ```
    pub fn solve(&self, board: SymbolicState) -> Result<Vec<MoveId>, GameError> {
        Ok(self.optimal_moves(board)?.ones().collect())
    }

    /// The solution depth of `board` (length of a shortest solution).
    pub fn depth(&self, board: SymbolicState) -> Result<usize, GameError> {
        Ok(self.optimal_moves(board)?.count_ones() as usize)
    }

    /// The lightest solution vector; ties go to the first found in Gray-code order.
    fn optimal_moves(&self, board: SymbolicState) -> Result<SymbolicState, GameError> {
        if !self.is_solvable(board) {
            return Err(GameError::Unsolvable { game: "lightsout" });
        }
        let mut x = SymbolicState::ZERO;
        for (r, &p) in self.pivots.iter().enumerate() {
            if parity(self.transform[r] & board) {
                x.set(p, true);
            }
        }
        let mut best = x;
        for i in 1u64..(1 << self.kernel.len()) {
            x ^= self.kernel[i.trailing_zeros() as usize];
            if x.count_ones() < best.count_ones() {
                best = x;
            }
        }
        Ok(best)
    }
}

fn parity(z: SymbolicState) -> bool {
    z.count_ones() % 2 == 1
}
