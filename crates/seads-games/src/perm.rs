//! Permutations of the tiles on a board: their one-hot symbolic states (bit `cells·p + t` is 1
//! iff tile t lies in cell p) and their Lehmer ranks, shared by TileSwap and the sliding puzzle.

use crate::SymbolicState;

/// n! for n = 0..9.
pub(crate) const FACTORIAL: [u32; 10] = [1, 1, 2, 6, 24, 120, 720, 5040, 40320, 362880];

/// Lehmer rank of a permutation of 0..9 (lexicographic order, identity = 0).
pub(crate) fn rank(perm: &[u8; 9]) -> u32 {
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
pub(crate) fn unrank(mut r: u32) -> [u8; 9] {
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

/// The one-hot symbolic state of `tiles` (the tile in each cell).
pub(crate) fn one_hot(tiles: &[u8]) -> SymbolicState {
    let cells = tiles.len();
    let mut z = SymbolicState::ZERO;
    for (p, &t) in tiles.iter().enumerate() {
        z.set(cells * p + t as usize, true);
    }
    z
}

/// The tile in each of `out.len()` cells of a one-hot state (the lowest set bit of each block).
pub(crate) fn tiles_of(z: SymbolicState, out: &mut [u8]) {
    let cells = out.len();
    for (p, o) in out.iter_mut().enumerate() {
        *o = (0..cells).find(|&t| z.get(cells * p + t)).unwrap_or(0) as u8;
    }
}

/// Whether `z` is the one-hot state of a permutation of `cells` tiles, with no bit set past it.
pub(crate) fn is_one_hot_permutation(z: SymbolicState, cells: usize) -> bool {
    if z.ones().any(|d| d >= cells * cells) {
        return false;
    }
    let mut seen = vec![false; cells];
    for p in 0..cells {
        let mut block = (0..cells).filter(|&t| z.get(cells * p + t));
        match (block.next(), block.next()) {
            (Some(t), None) if !seen[t] => seen[t] = true,
            _ => return false,
        }
    }
    true
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
    fn one_hot_round_trips_and_is_checked() {
        let tiles: Vec<u8> = vec![3, 0, 15, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14];
        let z = one_hot(&tiles);
        assert_eq!(z.count_ones(), 16);
        assert!(z.get(16 * 2 + 15), "tile 15 in cell 2: bit 47");
        let mut back = [0u8; 16];
        tiles_of(z, &mut back);
        assert_eq!(back.to_vec(), tiles);
        assert!(is_one_hot_permutation(z, 16));
        let mut twice = z;
        twice.set(16 + 3, true); // cell 1, tile 3
        assert!(!is_one_hot_permutation(twice, 16), "cell 1 holds two tiles");
        assert!(
            !is_one_hot_permutation(one_hot(&[0, 0, 2]), 3),
            "tile 0 twice"
        );
        let mut beyond = one_hot(&[0, 1, 2]);
        beyond.set(9, true);
        assert!(!is_one_hot_permutation(beyond, 3));
    }
}
