//! The sliding-tile puzzle: the 8-puzzle on 3×3 and the 15-puzzle on 4×4. A move pushes a field;
//! if it holds a tile next to the gap, the tile slides into the gap, and any other push does
//! nothing. Unlike LightsOut's and TileSwap's, its moves thus depend on the state.

use std::sync::OnceLock;

use rand::seq::SliceRandom;
use rand::{RngExt, seq::IndexedRandom as _};

use crate::perm::{FACTORIAL, is_one_hot_permutation, one_hot, rank, tiles_of, unrank};
use crate::{
    BoardGame, DepthTable, Enumerable, FieldMark, GameEntry, GameError, GameKind, MAX_DRAWS,
    MoveId, MoveSite, SolveControl, Split, SymbolicState, split_of,
};

/// The sliding puzzle in the registry.
pub(crate) static ENTRY: GameEntry = GameEntry {
    name: "sliding",
    title: "Sliding",
    description: "the sliding-tile puzzle, 3×3 (8-puzzle) or 4×4 (15-puzzle): push a tile next to the gap into it",
    default_size: 3,
    build: |size| Ok(Box::new(SlidingPuzzle::new(size)?)),
};

/// Largest board side: 16 cells of 16 tiles fill a 256-bit [`SymbolicState`].
const MAX_CELLS: usize = 16;

/// Search nodes the 15-puzzle's sampler may spend on drawing one board deeper than the listed
/// depths: past them a reset says that no board of that depth was found, instead of drawing
/// for minutes (the random walks rarely stay optimal past about 45 moves).
const SAMPLE_NODES: u64 = 400_000_000;

/// Depths up to which the 15-puzzle's boards of one depth are listed, to draw among them and to
/// tell whether a split lacks them (depth 12 has 7,808 boards); deeper layers hold many boards in
/// both splits.
const LISTED_DEPTHS: usize = 12;

/// The sliding puzzle on an N×N board, N ∈ {3, 4}. A board holds a permutation of the tile ids
/// 0..N²−1, where 0 is the gap; the goal has tile `1 + p` at cell p and the gap in the last cell.
/// Bit `N²·p + t` of z is 1 iff tile t (0: the gap) lies in cell p. Move p pushes field p.
#[derive(Debug, Clone)]
pub struct SlidingPuzzle {
    n: usize,
    /// The boards of each depth up to [`LISTED_DEPTHS`], listed on first use: every reset at a
    /// shallow depth draws among them.
    layers: OnceLock<Vec<Vec<SymbolicState>>>,
}

impl SlidingPuzzle {
    /// The puzzle of side `n` (3: the 8-puzzle, 4: the 15-puzzle).
    pub fn new(n: usize) -> Result<Self, GameError> {
        if (3..=4).contains(&n) {
            Ok(Self {
                n,
                layers: OnceLock::new(),
            })
        } else {
            Err(GameError::UnsupportedSize {
                game: "sliding",
                size: n,
                allowed: "3 or 4",
            })
        }
    }

    fn cells(&self) -> usize {
        self.n * self.n
    }

    /// The tile in each cell.
    fn tiles(&self, board: SymbolicState) -> Tiles {
        let mut tiles = Tiles::default();
        tiles_of(board, &mut tiles.0[..self.cells()]);
        tiles
    }

    /// The cell of the gap.
    fn gap(&self, board: SymbolicState) -> usize {
        let cells = self.cells();
        (0..cells).find(|&p| board.get(cells * p)).unwrap_or(0)
    }

    /// Whether cells `p` and `q` share an edge.
    fn adjacent(&self, p: usize, q: usize) -> bool {
        let n = self.n;
        let (pr, pc, qr, qc) = (p / n, p % n, q / n, q % n);
        pr.abs_diff(qr) + pc.abs_diff(qc) == 1
    }

    /// The class of boards that slides connect: the parity of the permutation (the gap counted
    /// as a tile) plus the parity of the gap's row and column. Every slide flips both, and two
    /// boards of one class are connected (Johnson and Story, 1879).
    fn class(&self, tiles: &[u8]) -> bool {
        let mut inversions = 0;
        for i in 0..tiles.len() {
            for j in i + 1..tiles.len() {
                inversions += usize::from(tiles[i] > tiles[j]);
            }
        }
        let gap = tiles.iter().position(|&t| t == 0).unwrap_or(0);
        (inversions + gap / self.n + gap % self.n) % 2 == 1
    }

    /// The boards of solution depth `depth` ≤ [`LISTED_DEPTHS`], by breadth-first search from
    /// the goal (once per game).
    fn layer(&self, depth: usize) -> &[SymbolicState] {
        let layers = self.layers.get_or_init(|| {
            let goal = self.goal();
            let mut seen = std::collections::BTreeSet::from([goal]);
            let mut layers = vec![vec![goal]];
            for _ in 0..LISTED_DEPTHS {
                let mut next = Vec::new();
                for &board in layers.last().expect("the goal layer") {
                    for mv in 0..self.cells() {
                        let after = self.apply(board, mv);
                        if seen.insert(after) {
                            next.push(after);
                        }
                    }
                }
                layers.push(next);
            }
            layers
        });
        &layers[depth]
    }
}

/// Tiles per cell, room for the largest board.
#[derive(Clone, Copy, Default)]
struct Tiles([u8; MAX_CELLS]);

impl BoardGame for SlidingPuzzle {
    fn kind(&self) -> GameKind {
        GameKind::of(&ENTRY)
    }
    fn size(&self) -> usize {
        self.n
    }
    fn num_moves(&self) -> usize {
        self.cells()
    }
    fn symbolic_len(&self) -> usize {
        self.cells() * self.cells()
    }
    fn goal(&self) -> SymbolicState {
        let cells = self.cells();
        let tiles: Vec<u8> = (0..cells).map(|p| ((p + 1) % cells) as u8).collect();
        one_hot(&tiles)
    }
    fn apply(&self, board: SymbolicState, mv: MoveId) -> SymbolicState {
        let cells = self.cells();
        let gap = self.gap(board);
        if !self.adjacent(mv, gap) {
            return board;
        }
        let tile = (0..cells).find(|&t| board.get(cells * mv + t)).unwrap_or(0);
        let mut after = board;
        after.set(cells * mv + tile, false);
        after.set(cells * mv, true);
        after.set(cells * gap, false);
        after.set(cells * gap + tile, true);
        after
    }
    fn values(&self, board: SymbolicState) -> Vec<u8> {
        self.tiles(board).0[..self.cells()].to_vec()
    }
    fn write_values(&self, board: SymbolicState, out: &mut [u8]) {
        tiles_of(board, out);
    }
    fn board_from_values(&self, values: &[u8]) -> Result<SymbolicState, GameError> {
        let cells = self.cells();
        if values.len() != cells {
            return Err(GameError::WrongLength {
                game: "sliding",
                expected: cells,
                found: values.len(),
            });
        }
        let mut counts = [0usize; MAX_CELLS];
        for (index, &v) in values.iter().enumerate() {
            if v as usize >= cells {
                return Err(GameError::BadSymbol {
                    game: "sliding",
                    index,
                    symbol: v.to_string(),
                    allowed: self.allowed_values(),
                });
            }
            counts[v as usize] += 1;
        }
        if let Some(tile) = (0..cells).find(|&t| counts[t] != 1) {
            return Err(GameError::NotPermutation {
                game: "sliding",
                last: (cells - 1) as u8,
                tile: tile as u8,
                count: counts[tile],
            });
        }
        Ok(one_hot(values))
    }
    fn is_valid(&self, z: SymbolicState) -> bool {
        is_one_hot_permutation(z, self.cells())
    }
    fn allowed_values(&self) -> &'static str {
        match self.n {
            3 => "a tile id 0..8 (0: the gap)",
            _ => "a tile id 0..15 (0: the gap)",
        }
    }
    fn move_site(&self, mv: MoveId) -> MoveSite {
        MoveSite::Field(mv)
    }
    fn field_mark(&self, value: u8) -> FieldMark {
        if value == 0 {
            FieldMark::Blank
        } else {
            FieldMark::Label(value.to_string())
        }
    }
    /// Any arrangement of the tiles; half of them cannot reach the goal.
    fn random_board(&self, rng: &mut dyn rand::Rng) -> SymbolicState {
        let mut tiles: Vec<u8> = (0..self.cells() as u8).collect();
        tiles.shuffle(rng);
        one_hot(&tiles)
    }
    /// The 8-puzzle (9! indices, half of them reachable).
    fn enumerable(&self) -> Option<&dyn Enumerable> {
        (self.n == 3).then_some(self as &dyn Enumerable)
    }
    /// A board of exactly `depth` in `split`: drawn among the listed boards of that depth up to
    /// depth 12 (`LISTED_DEPTHS`); deeper, a random walk of `depth` slides that never undoes the
    /// last one, kept when the solver finds it that deep and it lies in `split`. The 15-puzzle's
    /// solver is bounded by `SAMPLE_NODES` search nodes over all draws: `None` once they are spent.
    fn sample_at_depth(
        &self,
        depth: usize,
        split: Split,
        rng: &mut dyn rand::Rng,
    ) -> Option<SymbolicState> {
        if depth <= LISTED_DEPTHS {
            return self
                .layer(depth)
                .iter()
                .copied()
                .filter(|&b| split_of(&self.values(b)) == split)
                .collect::<Vec<_>>()
                .choose(rng)
                .copied();
        }
        let control = SolveControl::new(SAMPLE_NODES);
        let mut budget = Budget::new(&control);
        for _ in 0..MAX_DRAWS {
            let mut board = self.goal();
            let mut last_gap = usize::MAX;
            for _ in 0..depth {
                let gap = self.gap(board);
                let options: Vec<usize> = (0..self.cells())
                    .filter(|&p| self.adjacent(p, gap) && p != last_gap)
                    .collect();
                let mv = options[rng.random_range(0..options.len())];
                board = self.apply(board, mv);
                last_gap = gap;
            }
            if split_of(&self.values(board)) != split {
                continue;
            }
            let found = if self.n == 3 {
                self.solution_depth(board).and_then(Result::ok)
            } else {
                // The budget left is spent over the draws; once it is gone, no board is found.
                Some(ida_star(self.n, &self.tiles(board).0[..self.cells()], &mut budget)?.len())
            };
            if found == Some(depth) {
                return Some(board);
            }
        }
        None
    }
    fn lacks_boards(&self, depth: usize, split: Split) -> bool {
        depth <= LISTED_DEPTHS
            && !self
                .layer(depth)
                .iter()
                .any(|&b| split_of(&self.values(b)) == split)
    }
    /// Slides connect exactly the boards of one class.
    fn can_reach(&self, from: SymbolicState, to: SymbolicState) -> Option<bool> {
        let cells = self.cells();
        let (a, b) = (self.tiles(from), self.tiles(to));
        Some(self.class(&a.0[..cells]) == self.class(&b.0[..cells]))
    }
    /// The 8-puzzle from its complete depth table, the 15-puzzle by IDA* with the Manhattan
    /// distance (fast to a depth of about 40; the hardest boards take 80 moves and much longer),
    /// within [`crate::SOLVE_NODES`] search nodes.
    fn solve(&self, board: SymbolicState) -> Option<Result<Vec<MoveId>, GameError>> {
        self.solve_within(board, &SolveControl::default())
    }
    fn solve_within(
        &self,
        board: SymbolicState,
        control: &SolveControl,
    ) -> Option<Result<Vec<MoveId>, GameError>> {
        let unsolvable = GameError::Unsolvable { game: "sliding" };
        if !self.is_valid(board) || self.can_reach(board, self.goal()) != Some(true) {
            return Some(Err(unsolvable));
        }
        Some(if self.n == 3 {
            eight_puzzle_table().solve(self, board)
        } else {
            let mut budget = Budget::new(control);
            let solved = ida_star(self.n, &self.tiles(board).0[..self.cells()], &mut budget);
            control.set_expanded(budget.taken);
            solved.ok_or(if control.is_stopped() {
                GameError::Interrupted { game: "sliding" }
            } else {
                GameError::SearchLimit {
                    game: "sliding",
                    nodes: control.max_nodes(),
                }
            })
        })
    }
    fn solution_depth(&self, board: SymbolicState) -> Option<Result<usize, GameError>> {
        if self.n == 3 {
            let unsolvable = GameError::Unsolvable { game: "sliding" };
            if !self.is_valid(board) {
                return Some(Err(unsolvable));
            }
            return Some(
                eight_puzzle_table()
                    .depth(self, board)
                    .map(usize::from)
                    .ok_or(unsolvable),
            );
        }
        self.solve(board).map(|moves| moves.map(|m| m.len()))
    }
}

impl Enumerable for SlidingPuzzle {
    fn index_space(&self) -> Option<u64> {
        (self.n == 3).then_some(FACTORIAL[9] as u64)
    }
    fn index_of(&self, board: SymbolicState) -> u32 {
        let mut tiles = [0u8; 9];
        tiles_of(board, &mut tiles);
        rank(&tiles)
    }
    fn board_at(&self, index: u32) -> SymbolicState {
        one_hot(&unrank(index))
    }
}

/// The 8-puzzle's complete depth table, shared by the process.
fn eight_puzzle_table() -> &'static DepthTable {
    static TABLE: OnceLock<DepthTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        DepthTable::build(&SlidingPuzzle::new(3).expect("3×3")).expect("the 8-puzzle enumerates")
    })
}

/// What an IDA* search may still do: the nodes left to expand under its [`SolveControl`],
/// which it looks at on the first node and every [`Budget::CHECK_EVERY`] nodes after it
/// (stopped? then it ends) and tells how many nodes it has taken.
struct Budget<'a> {
    left: u64,
    taken: u64,
    control: &'a SolveControl,
}

impl<'a> Budget<'a> {
    const CHECK_EVERY: u64 = 1 << 16;

    fn new(control: &'a SolveControl) -> Self {
        Self {
            left: control.max_nodes(),
            taken: 0,
            control,
        }
    }

    /// Takes one node off the budget; `false` once none is left or the search was stopped.
    fn take(&mut self) -> bool {
        if self.left == 0 {
            return false;
        }
        if self.taken.is_multiple_of(Self::CHECK_EVERY) {
            self.control.set_expanded(self.taken);
            if self.control.is_stopped() {
                self.left = 0;
                return false;
            }
        }
        self.left -= 1;
        self.taken += 1;
        true
    }
}

/// A shortest solution of a solvable board (`tiles` per cell) by iterative-deepening A* with
/// the Manhattan distance of every tile from its goal cell, an admissible bound; `None` once
/// `budget` is spent (each node it expands is taken off it) or stopped.
fn ida_star(n: usize, tiles: &[u8], budget: &mut Budget<'_>) -> Option<Vec<MoveId>> {
    let cells = n * n;
    // Tile t's goal cell is t − 1; the gap's is the last.
    let home = |t: u8| if t == 0 { cells - 1 } else { t as usize - 1 };
    let distance = |t: u8, p: usize| {
        let h = home(t);
        (h / n).abs_diff(p / n) + (h % n).abs_diff(p % n)
    };
    let mut tiles = tiles.to_vec();
    let h: usize = (0..cells)
        .filter(|&p| tiles[p] != 0)
        .map(|p| distance(tiles[p], p))
        .sum();
    let gap = tiles.iter().position(|&t| t == 0).unwrap_or(0);
    let mut path = Vec::new();
    let mut bound = h;
    loop {
        match search(
            n,
            &mut tiles,
            gap,
            usize::MAX,
            h,
            bound,
            &mut path,
            &distance,
            budget,
        ) {
            Found::Yes => return Some(path),
            Found::No(next) => bound = next,
            Found::Spent => return None,
        }
    }
}

/// What one IDA* pass found: a solution, the least cost past its bound, or nothing before its
/// node budget ran out.
enum Found {
    Yes,
    No(usize),
    Spent,
}

/// One depth-first pass of IDA* under `bound`: `path` holds the pushes made so far, `from` the
/// cell the gap left last (pushing it would slide the tile back).
#[allow(clippy::too_many_arguments)]
fn search(
    n: usize,
    tiles: &mut [u8],
    gap: usize,
    from: usize,
    h: usize,
    bound: usize,
    path: &mut Vec<MoveId>,
    distance: &dyn Fn(u8, usize) -> usize,
    budget: &mut Budget<'_>,
) -> Found {
    if !budget.take() {
        return Found::Spent;
    }
    let f = path.len() + h;
    if f > bound {
        return Found::No(f);
    }
    if h == 0 {
        return Found::Yes;
    }
    let mut least = usize::MAX;
    let (r, c) = (gap / n, gap % n);
    let neighbours = [
        (r > 0).then(|| gap - n),
        (r + 1 < n).then(|| gap + n),
        (c > 0).then(|| gap - 1),
        (c + 1 < n).then(|| gap + 1),
    ];
    for p in neighbours.into_iter().flatten().filter(|&p| p != from) {
        let tile = tiles[p];
        let h_after = h + distance(tile, gap) - distance(tile, p);
        tiles[gap] = tile;
        tiles[p] = 0;
        path.push(p);
        match search(n, tiles, p, gap, h_after, bound, path, distance, budget) {
            Found::Yes => return Found::Yes,
            Found::No(t) => least = least.min(t),
            Found::Spent => return Found::Spent,
        }
        path.pop();
        tiles[p] = tile;
        tiles[gap] = 0;
    }
    Found::No(least)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::enumerate;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// The 8-puzzle's boards per solution depth with the gap in a corner: Reinefeld's table
    /// (1993, "Complete solution of the eight-puzzle"): 181,440 reachable boards, two at depth 31.
    #[test]
    fn eight_puzzle_depth_counts_match_the_published_table() {
        let counts = enumerate(&SlidingPuzzle::new(3).unwrap(), None)
            .unwrap()
            .depth_counts();
        let published: [u64; 32] = [
            1, 2, 4, 8, 16, 20, 39, 62, 116, 152, 286, 396, 748, 1024, 1893, 2512, 4485, 5638,
            9529, 10878, 16993, 17110, 23952, 20224, 24047, 15578, 14560, 6274, 3910, 760, 221, 2,
        ];
        assert_eq!(counts, published);
        assert_eq!(counts.iter().sum::<u64>(), 181_440);
    }

    #[test]
    fn a_push_slides_only_a_tile_next_to_the_gap() {
        let g = SlidingPuzzle::new(3).unwrap();
        let goal = g.goal();
        assert_eq!(g.format(goal), "1,2,3,4,5,6,7,8,0");
        // The gap is in cell 8: cells 5 and 7 slide, every other push does nothing.
        assert_eq!(g.format(g.apply(goal, 5)), "1,2,3,4,5,0,7,8,6");
        assert_eq!(g.format(g.apply(goal, 7)), "1,2,3,4,5,6,7,0,8");
        for mv in [0, 1, 2, 3, 4, 6, 8] {
            assert_eq!(g.apply(goal, mv), goal, "push {mv}");
            assert!(!g.changes(goal, mv));
        }
        // Pushing the field the gap left slides the tile back.
        let once = g.apply(goal, 5);
        assert_eq!(g.apply(once, 8), goal);
        assert!(g.is_valid(once));
        assert_eq!(
            g.field_mark(0),
            FieldMark::Blank,
            "the gap is shown as nothing"
        );
    }

    #[test]
    fn bad_boards_are_refused_in_words() {
        let g = SlidingPuzzle::new(3).unwrap();
        let err = g.parse("1,2,3,4,5,6,7,8,8").unwrap_err();
        assert!(err.to_string().contains("tile 0 appears 0 times"), "{err}");
        assert!(g.parse("1,2,3,4,5,6,7,8,9").is_err());
        assert!(SlidingPuzzle::new(5).is_err());
        // Two tiles swapped: the other class, never solved.
        let swapped = g.parse("2,1,3,4,5,6,7,8,0").unwrap();
        assert_eq!(g.can_reach(swapped, g.goal()), Some(false));
        assert!(g.solve(swapped).unwrap().is_err());
        let g4 = SlidingPuzzle::new(4).unwrap();
        let swapped = g4.parse("2,1,3,4,5,6,7,8,9,10,11,12,13,14,15,0").unwrap();
        assert!(g4.solve(swapped).unwrap().is_err());
    }

    /// IDA* on the 8-puzzle agrees with the complete depth table on boards of every depth, and
    /// its pushes solve the board.
    #[test]
    fn ida_star_agrees_with_breadth_first_depths() {
        let g = SlidingPuzzle::new(3).unwrap();
        let e = enumerate(&g, None).unwrap();
        for d in 0..=e.max_depth() {
            for &index in e.layer(d).iter().step_by(e.layer(d).len().div_ceil(6)) {
                let board = g.board_at(index);
                let tiles = g.values(board);
                let control = SolveControl::new(u64::MAX);
                let moves = ida_star(3, &tiles, &mut Budget::new(&control)).unwrap();
                assert_eq!(moves.len(), d, "board {}", g.format(board));
                assert!(g.is_goal(g.apply_all(board, &moves)));
            }
        }
    }

    /// The 15-puzzle: IDA* solves boards of depths to 12 optimally (breadth-first layers), and
    /// a 60-slide random walk in at most 60 slides of the walk's parity.
    #[test]
    fn fifteen_puzzle_solutions_are_optimal() {
        let g = SlidingPuzzle::new(4).unwrap();
        assert!(g.enumerable().is_none());
        for d in [0, 1, 2, 5, 9, 12] {
            for &board in g.layer(d).iter().take(5) {
                let moves = g.solve(board).unwrap().unwrap();
                assert_eq!(moves.len(), d);
                assert!(g.is_goal(g.apply_all(board, &moves)));
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut board = g.goal();
        for _ in 0..60 {
            board = g.apply(board, rng.random_range(0..16));
        }
        let moves = g.solve(board).unwrap().unwrap();
        assert!(g.is_goal(g.apply_all(board, &moves)));
        assert!(moves.len() <= 60);
        // Within a bound of search nodes (issue 82: a deep board was searched for without an
        // end): a bound too small for the board is said, one large enough solves it alike.
        // A board of depth 12 takes at least 13 nodes: 12 are too few.
        let board = g.layer(12)[0];
        let moves = g.solve(board).unwrap().unwrap();
        let few = SolveControl::new(12);
        let stopped = g.solve_within(board, &few).unwrap().unwrap_err();
        assert!(
            matches!(stopped, GameError::SearchLimit { nodes: 12, .. }),
            "{stopped}"
        );
        assert_eq!(few.expanded(), 12, "the bound's nodes were all expanded");
        let enough = SolveControl::new(u64::MAX);
        assert_eq!(g.solve_within(board, &enough).unwrap().unwrap(), moves);
        // The nodes it took are counted (issue 82: a long solve showed no progress): at least
        // one per layer of the solution, and within the least bound that solves it.
        let expanded = enough.expanded();
        assert!(expanded > 12, "{expanded} nodes");
        let just = SolveControl::new(expanded);
        assert_eq!(g.solve_within(board, &just).unwrap().unwrap(), moves);
        let short = SolveControl::new(expanded - 1);
        assert!(g.solve_within(board, &short).unwrap().is_err());
        // A raised flag stops the search at its next look (another thread raises it: Ctrl-C).
        let stop = SolveControl::new(u64::MAX);
        stop.stop();
        let interrupted = g.solve_within(board, &stop).unwrap().unwrap_err();
        assert!(
            matches!(interrupted, GameError::Interrupted { .. }),
            "{interrupted}"
        );
    }

    /// Boards drawn at a depth have exactly that depth and lie in the split, past the listed
    /// depths too; a split a shallow depth lacks is said beforehand.
    #[test]
    fn fifteen_puzzle_boards_are_drawn_at_their_depth() {
        let g = SlidingPuzzle::new(4).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for depth in [3, 8, 14, 18] {
            for split in [Split::Train, Split::Test] {
                if g.lacks_boards(depth, split) {
                    assert!(g.sample_at_depth(depth, split, &mut rng).is_none());
                    continue;
                }
                let board = g.sample_at_depth(depth, split, &mut rng).unwrap();
                assert_eq!(split_of(&g.values(board)), split);
                assert_eq!(g.solution_depth(board).unwrap().unwrap(), depth);
            }
        }
        // A depth whose boards the random walks do not reach within the sampler's bound of
        // search nodes: no board, found out in bounded time (issue 82: depth 55 drew for 102 s,
        // then a reset panicked).
        assert!(g.sample_at_depth(200, Split::Test, &mut rng).is_none());
        // Depth 1 has two boards (the gap left or up); at most both splits hold them.
        let listed: usize = [Split::Train, Split::Test]
            .iter()
            .filter(|&&s| !g.lacks_boards(1, s))
            .count();
        assert!(listed >= 1);
    }
}
