//! Where on the board a push lands: normalised board coordinates → game move (SPEC §1.6, §2.2).
//!
//! Coordinates are normalised to the board: u ∈ [0, 1] selects the column (left to right), v ∈
//! [0, 1] the row (row 0 at v = 0), as for the Cursor whose origin is the top-left corner.

use seads_games::{BoardGame, MoveId, MoveSite};

/// The 12 TileSwap pivots `(u, v, move id)`, in the reference's order and computed with its
/// floating-point formulas: pushes exactly on a diamond's edge (field centres lie on four edges)
/// resolve as in the reference.
fn pivots() -> [(f64, f64, MoveId); 12] {
    let field = 1.0 / 3.0;
    let mut out = [(0.0, 0.0, 0); 12];
    let mut i = 0;
    for row in 0..3usize {
        for col in 0..3usize {
            if row != 2 {
                // Swap with the cell below: move id 2·col + row (SPEC §1.2).
                out[i] = (
                    0.5 * field + field * col as f64,
                    (row + 1) as f64 * field,
                    2 * col + row,
                );
                i += 1;
            }
            if col != 2 {
                // Swap with the cell to the right: move id 6 + 3·col + row.
                out[i] = (
                    field * (col + 1) as f64,
                    0.5 * field + row as f64 * field,
                    6 + 3 * col + row,
                );
                i += 1;
            }
        }
    }
    out
}

/// Side of a field on a spaced LightsOut board: 1/13, whatever N (constant actionable area).
const SPACED_FIELD: f64 = 1.0 / 13.0;

/// How pushes on the unit board square map to moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Layout {
    /// LightsOut N×N whose fields tile the unit square: every push hits a field.
    Grid {
        /// Board side N.
        n: usize,
    },
    /// LightsOut N×N with fields of side 1/13 separated by gaps (SPEC §1.6).
    Spaced {
        /// Board side N (odd, 5..=13).
        n: usize,
        /// Relative spacing s ∈ [0, 1]: 0 packs the fields in the centre, 1 pushes the outer
        /// fields to the border.
        spacing: f64,
    },
    /// LightsOut N×N whose fields tile the unit square but are numbered column by column: the
    /// field in row r, column c is move c·N + r. The reference builds LightsOut3DJaco's board
    /// this way; LightsOut is symmetric under transposition, so the game is the same and only
    /// which physical field carries which bit of the board differs.
    ColumnMajor {
        /// Board side N.
        n: usize,
    },
    /// TileSwap 3×3: a push within L1 distance 1/6 of one of 12 pivots swaps its two tiles.
    Pivots,
}

impl Layout {
    /// The standard layout of a game: fields tiling the square where its moves are made at
    /// fields, the pivots where they are made between the fields of a 3×3 board (TileSwap);
    /// `None` for a game whose moves neither layout places.
    pub fn standard(game: &dyn BoardGame) -> Option<Self> {
        let n = game.size();
        let at = |mv| game.move_site(mv);
        if (0..game.num_moves()).all(|mv| at(mv) == MoveSite::Field(mv)) {
            return Some(Layout::Grid { n });
        }
        let pivots = pivots();
        let edges_match = game.num_moves() == pivots.len()
            && pivots.iter().all(|&(u, v, mv)| {
                // The pivot lies on the edge between the two fields the game names.
                matches!(at(mv), MoveSite::Edge(p, q) if {
                    let centre = |f: usize| ((f % 3) as f64 + 0.5, (f / 3) as f64 + 0.5);
                    let ((pu, pv), (qu, qv)) = (centre(p), centre(q));
                    ((pu + qu) / 6.0 - u).abs() < 1e-9 && ((pv + qv) / 6.0 - v).abs() < 1e-9
                })
            });
        (n == 3 && edges_match).then_some(Layout::Pivots)
    }

    /// The move triggered by a push at (u, v), or `None` if the push hits no move.
    pub fn locate(&self, u: f64, v: f64) -> Option<MoveId> {
        match *self {
            Layout::Grid { n } => Some(grid_bin(v, n) * n + grid_bin(u, n)),
            Layout::ColumnMajor { n } => Some(grid_bin(u, n) * n + grid_bin(v, n)),
            Layout::Spaced { n, spacing } => {
                let centres = spaced_centres(n, spacing);
                let hit = |x: f64| {
                    centres
                        .iter()
                        .position(|&c| (x - c).abs() < SPACED_FIELD / 2.0)
                };
                Some(hit(v)? * n + hit(u)?)
            }
            Layout::Pivots => {
                let (mut best, mut best_d) = (0, f64::INFINITY);
                for (px, py, mv) in pivots() {
                    let d = (px - u).abs() + (py - v).abs();
                    if d < best_d {
                        (best, best_d) = (mv, d);
                    }
                }
                (best_d <= (1.0 / 3.0) / 2.0).then_some(best)
            }
        }
    }

    /// The move of the field in row-major position `index` (row `index / N`, column
    /// `index % N`); `None` past the last field.
    pub fn field_move(&self, index: usize) -> Option<MoveId> {
        let n = match *self {
            Layout::Grid { n } | Layout::Spaced { n, .. } | Layout::ColumnMajor { n } => n,
            Layout::Pivots => 3,
        };
        if index >= n * n {
            return None;
        }
        Some(match self {
            Layout::ColumnMajor { .. } => (index % n) * n + index / n,
            _ => index,
        })
    }

    /// The fields as rectangles `[u0, v0, u1, v1]`, in the order of their moves (row-major but
    /// for [`Layout::ColumnMajor`]).
    pub fn fields(&self) -> Vec<[f64; 4]> {
        match *self {
            Layout::ColumnMajor { n } => {
                let row_major = Layout::Grid { n }.fields();
                (0..n * n)
                    .map(|mv| row_major[(mv % n) * n + mv / n])
                    .collect()
            }
            Layout::Grid { n } => square_fields(
                &(0..n)
                    .map(|i| (i as f64 + 0.5) / n as f64)
                    .collect::<Vec<_>>(),
                1.0 / n as f64,
            ),
            Layout::Spaced { n, spacing } => {
                square_fields(&spaced_centres(n, spacing), SPACED_FIELD)
            }
            Layout::Pivots => square_fields(&[1.0 / 6.0, 0.5, 5.0 / 6.0], 1.0 / 3.0),
        }
    }

    /// The TileSwap pivot points `(u, v)` (empty for LightsOut).
    pub fn pivots(&self) -> Vec<(f64, f64)> {
        match self {
            Layout::Pivots => pivots().iter().map(|&(u, v, _)| (u, v)).collect(),
            _ => Vec::new(),
        }
    }
}

/// Right-closed bins (0, b₁], (b₁, b₂], … with b_i = i·(1/N) (NumPy's `linspace`, last edge 1);
/// 0 goes to bin 0.
fn grid_bin(x: f64, n: usize) -> usize {
    let width = 1.0 / n as f64;
    (1..n).filter(|&i| i as f64 * width < x).count()
}

/// Field centres along one axis of a spaced board.
fn spaced_centres(n: usize, spacing: f64) -> Vec<f64> {
    let free = 1.0 - n as f64 * SPACED_FIELD;
    let gap = if n > 1 {
        spacing * free / (n - 1) as f64
    } else {
        0.0
    };
    let pitch = SPACED_FIELD + gap;
    (0..n)
        .map(|i| 0.5 + (i as f64 - (n - 1) as f64 / 2.0) * pitch)
        .collect()
}

fn square_fields(centres: &[f64], side: f64) -> Vec<[f64; 4]> {
    let h = side / 2.0;
    centres
        .iter()
        .flat_map(|&v| centres.iter().map(move |&u| [u - h, v - h, u + h, v + h]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_bins_are_right_closed() {
        let g = Layout::Grid { n: 5 };
        assert_eq!(g.locate(0.0, 0.0), Some(0));
        assert_eq!(g.locate(0.2, 0.2), Some(0));
        assert_eq!(g.locate(0.2001, 0.0), Some(1));
        assert_eq!(
            g.locate(0.6, 0.6),
            Some(12),
            "0.6 ≤ linspace edge 0.6000000000000001"
        );
        assert_eq!(g.locate(1.0, 1.0), Some(24));
        assert_eq!(g.locate(0.5, 0.9), Some(22));
    }

    /// Column-major numbering: the field in row r, column c is move c·N + r, whether found by a
    /// push (`locate`), by a sensor's row-major position (`field_move`) or drawn (`fields`).
    #[test]
    fn column_major_grids_number_fields_column_by_column() {
        for n in 1..=7 {
            let (grid, columns) = (Layout::Grid { n }, Layout::ColumnMajor { n });
            let drawn = columns.fields();
            for (row, col) in (0..n).flat_map(|r| (0..n).map(move |c| (r, c))) {
                let (u, v) = ((col as f64 + 0.5) / n as f64, (row as f64 + 0.5) / n as f64);
                assert_eq!(grid.locate(u, v), Some(row * n + col));
                assert_eq!(columns.locate(u, v), Some(col * n + row));
                assert_eq!(grid.field_move(row * n + col), Some(row * n + col));
                assert_eq!(columns.field_move(row * n + col), Some(col * n + row));
                let [u0, v0, u1, v1] = drawn[col * n + row];
                assert!(
                    u0 < u && u < u1 && v0 < v && v < v1,
                    "n {n}: ({row}, {col})"
                );
            }
            assert_eq!(columns.field_move(n * n), None);
        }
    }

    #[test]
    fn pivots_match_the_table() {
        let p = Layout::Pivots;
        let table = [
            ((1.0 / 6.0, 1.0 / 3.0), 0),
            ((1.0 / 3.0, 1.0 / 6.0), 6),
            ((0.5, 1.0 / 3.0), 2),
            ((2.0 / 3.0, 1.0 / 6.0), 9),
            ((5.0 / 6.0, 1.0 / 3.0), 4),
            ((1.0 / 6.0, 2.0 / 3.0), 1),
            ((1.0 / 3.0, 0.5), 7),
            ((0.5, 2.0 / 3.0), 3),
            ((2.0 / 3.0, 0.5), 10),
            ((5.0 / 6.0, 2.0 / 3.0), 5),
            ((1.0 / 3.0, 5.0 / 6.0), 8),
            ((2.0 / 3.0, 5.0 / 6.0), 11),
        ];
        for ((u, v), mv) in table {
            assert_eq!(p.locate(u, v), Some(mv), "pivot at ({u}, {v})");
        }
    }

    #[test]
    fn outer_triangles_are_dead_and_centres_resolve_like_the_reference() {
        let p = Layout::Pivots;
        for (u, v) in [
            (0.0, 0.0),
            (1.0, 1.0),
            (0.5, 0.02),
            (0.02, 0.5),
            (0.98, 0.5),
            (0.5, 0.98),
        ] {
            assert_eq!(p.locate(u, v), None, "({u}, {v})");
        }
        // The centre of the middle field lies on four diamond edges; float rounding of the
        // reference formulas makes it the lower pivot (move 3).
        assert_eq!(p.locate(0.5, 0.5), Some(3));
        // Just inside a diamond.
        assert_eq!(p.locate(0.5, 0.34), Some(2));
    }

    #[test]
    fn spaced_layout_keeps_field_size_and_has_gaps() {
        let s = Layout::Spaced { n: 7, spacing: 1.0 };
        let f = s.fields();
        assert_eq!(f.len(), 49);
        assert!(
            (f[0][0]).abs() < 1e-12,
            "outer fields touch the border at s = 1"
        );
        assert!((f[0][2] - f[0][0] - 1.0 / 13.0).abs() < 1e-12);
        let centre = (f[24][0] + f[24][2]) / 2.0;
        assert_eq!(s.locate(centre, centre), Some(24));
        assert_eq!(
            s.locate((f[0][2] + f[1][0]) / 2.0, 0.5),
            None,
            "gap between fields"
        );
        let packed = Layout::Spaced { n: 5, spacing: 0.0 };
        assert_eq!(packed.locate(0.01, 0.01), None, "empty border at s = 0");
        assert_eq!(packed.locate(0.5, 0.5), Some(12));
    }
}
