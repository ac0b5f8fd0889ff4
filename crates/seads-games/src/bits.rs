//! `SymbolicState`: a fixed-size bitset holding a symbolic board observation z (up to 256 bits).

use serde::{Deserialize, Serialize};

/// Number of 64-bit words in a [`SymbolicState`].
const WORDS: usize = 4;

/// A binary symbolic state z, bit-packed: bit `d` is z_d.
///
/// 256 bits hold every game of the project (LightsOut up to 13×13 = 169 bits, TileSwap's 81-bit
/// one-hot matrix, the 15-puzzle's 256-bit one). Bits at or beyond the game's length D are always zero, so `==` and hashing
/// compare symbolic states exactly.
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct SymbolicState {
    words: [u64; WORDS],
}

impl SymbolicState {
    /// Number of 64-bit words.
    pub const WORDS: usize = WORDS;

    /// Largest number of bits a symbolic state can hold.
    pub const MAX_BITS: usize = 64 * WORDS;

    /// The all-zero state.
    pub const ZERO: Self = Self { words: [0; WORDS] };

    /// The state whose low 64 bits are `bits`.
    pub const fn from_u64(bits: u64) -> Self {
        Self {
            words: [bits, 0, 0, 0],
        }
    }

    /// The state whose low 128 bits are `bits`.
    pub const fn from_u128(bits: u128) -> Self {
        Self {
            words: [bits as u64, (bits >> 64) as u64, 0, 0],
        }
    }

    /// The low 64 bits.
    pub const fn low_u64(&self) -> u64 {
        self.words[0]
    }

    /// The low 128 bits.
    pub const fn low_u128(&self) -> u128 {
        self.words[0] as u128 | (self.words[1] as u128) << 64
    }

    /// The raw words, least significant first.
    pub const fn words(&self) -> [u64; WORDS] {
        self.words
    }

    /// Builds a state from its raw words, least significant first.
    pub const fn from_words(words: [u64; WORDS]) -> Self {
        Self { words }
    }

    /// Bit `d`.
    #[inline]
    pub fn get(&self, d: usize) -> bool {
        (self.words[d / 64] >> (d % 64)) & 1 == 1
    }

    /// Sets bit `d` to `value`.
    #[inline]
    pub fn set(&mut self, d: usize, value: bool) {
        let mask = 1u64 << (d % 64);
        if value {
            self.words[d / 64] |= mask;
        } else {
            self.words[d / 64] &= !mask;
        }
    }

    /// Flips bit `d`.
    #[inline]
    pub fn flip(&mut self, d: usize) {
        self.words[d / 64] ^= 1u64 << (d % 64);
    }

    /// Number of set bits.
    pub fn count_ones(&self) -> u32 {
        self.words.iter().map(|w| w.count_ones()).sum()
    }

    /// Whether no bit is set.
    pub fn is_zero(&self) -> bool {
        self.words == [0; WORDS]
    }

    /// Indices of the set bits, ascending.
    pub fn ones(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(|(w, &word)| {
            let mut rest = word;
            std::iter::from_fn(move || {
                if rest == 0 {
                    return None;
                }
                let bit = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                Some(w * 64 + bit)
            })
        })
    }

    /// The state with bit d = `bits[d]`. Panics if `bits` is longer than [`Self::MAX_BITS`].
    pub fn from_bools(bits: &[bool]) -> Self {
        assert!(
            bits.len() <= Self::MAX_BITS,
            "a symbolic state holds at most 256 bits"
        );
        let mut z = Self::ZERO;
        for (d, &b) in bits.iter().enumerate() {
            z.set(d, b);
        }
        z
    }

    /// The state read from an observation slice: a value is 1 iff it is non-zero (the Φ rule).
    pub fn from_observation(values: &[f32]) -> Self {
        assert!(
            values.len() <= Self::MAX_BITS,
            "a symbolic state holds at most 256 bits"
        );
        let mut z = Self::ZERO;
        for (d, &v) in values.iter().enumerate() {
            if v != 0.0 {
                z.set(d, true);
            }
        }
        z
    }

    /// The first `len` bits as booleans.
    pub fn to_bools(&self, len: usize) -> Vec<bool> {
        (0..len).map(|d| self.get(d)).collect()
    }

    /// Writes the first `out.len()` bits as 0.0 / 1.0.
    pub fn write_f32(&self, out: &mut [f32]) {
        for (d, o) in out.iter_mut().enumerate() {
            *o = if self.get(d) { 1.0 } else { 0.0 };
        }
    }
}

impl std::ops::BitXor for SymbolicState {
    type Output = Self;
    #[inline]
    fn bitxor(self, rhs: Self) -> Self {
        Self {
            words: std::array::from_fn(|i| self.words[i] ^ rhs.words[i]),
        }
    }
}

impl std::ops::BitXorAssign for SymbolicState {
    #[inline]
    fn bitxor_assign(&mut self, rhs: Self) {
        *self = *self ^ rhs;
    }
}

impl std::ops::BitAnd for SymbolicState {
    type Output = Self;
    #[inline]
    fn bitand(self, rhs: Self) -> Self {
        Self {
            words: std::array::from_fn(|i| self.words[i] & rhs.words[i]),
        }
    }
}

impl std::fmt::Debug for SymbolicState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SymbolicState(")?;
        for (i, w) in self.words.iter().rev().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{w:#x}")?;
        }
        write!(f, ")")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_get_flip_across_words() {
        let mut z = SymbolicState::ZERO;
        for d in [0, 63, 64, 127, 128, 191, 192, 255] {
            z.set(d, true);
            assert!(z.get(d));
        }
        assert_eq!(z.count_ones(), 8);
        assert_eq!(
            z.ones().collect::<Vec<_>>(),
            vec![0, 63, 64, 127, 128, 191, 192, 255]
        );
        z.flip(64);
        assert!(!z.get(64));
        z.set(0, false);
        assert_eq!(
            z.ones().collect::<Vec<_>>(),
            vec![63, 127, 128, 191, 192, 255]
        );
    }

    #[test]
    fn conversions_round_trip() {
        let bools: Vec<bool> = (0..81).map(|d| d % 3 == 0).collect();
        let z = SymbolicState::from_bools(&bools);
        assert_eq!(z.to_bools(81), bools);
        let mut f = vec![0.0; 81];
        z.write_f32(&mut f);
        assert_eq!(SymbolicState::from_observation(&f), z);
        assert_eq!(SymbolicState::from_u128(z.low_u128()), z);
    }
}
