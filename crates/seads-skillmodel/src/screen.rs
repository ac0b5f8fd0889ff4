//! The planner's successor function with the forward model's middle layer in 8-bit integers,
//! screened so that the successors stay exactly those of float32 inference.
//!
//! The mode of q flips bit d iff its flip logit is > 0 (SPEC §4.1), so only each logit's sign
//! matters. For a network `D+K → H₁ → H₂ → D` (the paper's two hidden layers):
//! - the first layer is computed in float32 as the float path does (its z₀ part once per state,
//!   the skill's column added per skill), giving the same h₁ ≥ 0;
//! - h₁ is quantised per row to i8 with scale s = max h₁ / 127, the second layer's weights per
//!   output unit with scale t_j = max_i |W_ji| / 127, and the product is exact in i32
//!   (libtorch's `_int_mm`, AVX-512 VNNI where the CPU has it);
//! - the output layer runs in float32 on the dequantised, rectified h₂.
//!
//! A batch goes through in blocks of 1,024 (state, skill) rows with reused buffers, and each
//! row's h₁ is built when it is read ([`Activations`]): a batch's activations are never held at
//! once, and a block's stay in cache (the successor function's cost halves against holding them;
//! `docs/results/screen-blocks/`).
//!
//! How far the float path's logit can lie from the screened one, two bounds:
//! - quick, per row from constants: with every error at half a step,
//!   s/2 · (Σ_j |V_lj| A_j + Q · Σ_j |V_lj| t_j), where A_j = Σ_i |W_ji| and Q = Σ_i q_i;
//! - tight, for the rows the quick one does not settle: the row's actual errors weighted by how
//!   much each moves the logit, Σ_i |h_i − s·q_i| C_li + s·q_i Σ_j |V_lj| |δW_ji| with
//!   C = |V| |W| and δW the weights' own quantisation error (one small float32 product).
//!
//! ReLU does not enlarge an error. Both bounds add a margin for float32 rounding, of this path
//! and of the float path, at γ = 10⁻⁴ per accumulated magnitude (sums of up to 1,024 terms stay
//! below 1,024 · 2⁻²⁴ ≈ 6·10⁻⁵; wider layers are not screened). A logit beyond its bound has the
//! float path's sign; a (state, skill) row with any logit within it, or with a NaN or infinite
//! activation, is computed by the float path. The successors therefore equal float32's (tested
//! against it on trained and untrained models, and the bound against f64 arithmetic and its
//! attained worst case); the screen only decides how much arithmetic that takes.

use tch::{Kind, Tensor};

/// Relative rounding margin per accumulated magnitude (float32 sums of ≤ 1,024 terms stay below
/// 1,024 · 2⁻²⁴ ≈ 6·10⁻⁵).
const GAMMA: f32 = 1e-4;
/// The widest layer the margin covers.
pub(crate) const MAX_WIDTH: i64 = 1024;
/// Integer products take this many rows at a time.
const ROW_STEP: usize = 1024;
/// Fewer (state, skill) rows than this go straight to float32: the integer product's fixed cost
/// per call outweighs its savings on small batches.
pub(crate) const MIN_ROWS: usize = 4096;

/// The second and third layers prepared for screened inference (built from the weights once,
/// rebuilt when they change).
#[derive(Debug)]
pub(crate) struct Int8Screen {
    h1: usize,
    h2: usize,
    d: usize,
    /// Quantised second-layer weights, H₁ × H₂ (transposed for `_int_mm`).
    w2: Tensor,
    /// Per output unit of the second layer: scale t_j and bias.
    t: Vec<f32>,
    b2: Vec<f32>,
    /// Output layer (float32), as a tensor for the product and its bias.
    w3_t: Tensor,
    b3: Vec<f32>,
    /// How far each logit can move per unit of quantisation error, 2H₁ × D: for logit l, row
    /// i < H₁ holds C_li = Σ_j |V_lj| |W_ji| (error of activation i), row H₁ + i holds
    /// Σ_j |V_lj| |δW_ji| (error of weight column i, per unit of activation).
    sensitivity: Tensor,
    /// Per logit l, the quick bound's constants: Σ_i C_li and Σ_j |V_lj| t_j.
    c_sum: Vec<f32>,
    v_t: Vec<f32>,
    /// Per logit l, for the rounding margin: Σ_j |V_lj| and Σ_j |V_lj| |b2_j|.
    v_abs: Vec<f32>,
    v_b2: Vec<f32>,
}

/// First-layer activations (≥ 0), one row of H₁ per (state, skill) pair, written on demand: a
/// batch's rows need not be held at once (the successor function builds each from its state's
/// part and its skill's column, `model.rs`).
pub(crate) trait Activations {
    /// Writes row `r`'s activations into `out` (H₁ values).
    fn write_row(&self, r: usize, out: &mut [f32]);
}

/// The tests' rows: a slice holds them one after another, H₁ = the row's length.
#[cfg(test)]
impl Activations for [f32] {
    fn write_row(&self, r: usize, out: &mut [f32]) {
        let h1 = out.len();
        out.copy_from_slice(&self[r * h1..(r + 1) * h1]);
    }
}

/// One batch through the screen: the screened logits and what their bounds need.
struct Screened {
    /// Screened logits, rows × D.
    logits: Vec<f32>,
    /// Quantised activations, rows × H₁, and per row their scale, sum, and max h₁ and h₂.
    q: Vec<i8>,
    scale: Vec<f32>,
    qsum: Vec<f32>,
    hmax: Vec<f32>,
    h2max: Vec<f32>,
}

/// The largest of non-negative values, NaN if one is NaN (as integers: the bit patterns of
/// non-negative floats order as the floats do, and NaN's lie above infinity's).
fn max_non_negative(x: &[f32]) -> f32 {
    f32::from_bits(x.iter().fold(0u32, |m, v| m.max(v.to_bits() & 0x7fff_ffff)))
}

/// The nearest integer (ties to even) of `x` in [0, 127 + 10⁻³], without a float-to-int
/// conversion: adding 1.5·2²³ leaves it in the low mantissa bits (vectorises on any x86-64).
/// Here x = v·(127 / max) may exceed v/s by a few ulp, which the bounds' margin covers.
fn nearest_level(x: f32) -> i8 {
    const MAGIC: f32 = 12_582_912.0;
    ((x + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits()) as i32).clamp(0, 127) as i8
}

/// Writes a row's flips (1 where the logit is positive) if every logit is clear of its bound.
fn settle(logits: &[f32], bound: impl Fn(usize) -> f32, out: &mut [u8]) -> bool {
    if !logits.iter().enumerate().all(|(l, x)| x.abs() > bound(l)) {
        return false;
    }
    for (f, &logit) in out.iter_mut().zip(logits) {
        *f = u8::from(logit > 0.0);
    }
    true
}

/// Float values of a CPU tensor.
fn floats(t: &Tensor) -> Vec<f32> {
    Vec::<f32>::try_from(t.to_kind(Kind::Float).contiguous().view([-1])).expect("float tensor")
}

impl Int8Screen {
    /// Another handle on the same screen, for another thread (a tensor is used from one thread
    /// at a time; the handles share their storage).
    pub(crate) fn shallow_clone(&self) -> Self {
        Self {
            w2: self.w2.shallow_clone(),
            t: self.t.clone(),
            b2: self.b2.clone(),
            w3_t: self.w3_t.shallow_clone(),
            b3: self.b3.clone(),
            sensitivity: self.sensitivity.shallow_clone(),
            c_sum: self.c_sum.clone(),
            v_t: self.v_t.clone(),
            v_abs: self.v_abs.clone(),
            v_b2: self.v_b2.clone(),
            ..*self
        }
    }

    /// Prepares layers 2 and 3 (`w2`: H₂ × H₁, `w3`: D × H₂, as `nn::Linear` holds them).
    pub(crate) fn new(w2: &Tensor, b2: &Tensor, w3: &Tensor, b3: &Tensor) -> Self {
        let (h2, h1) = (w2.size()[0] as usize, w2.size()[1] as usize);
        let d = w3.size()[0] as usize;
        let w2v = floats(w2);
        let w3v = floats(w3);
        let mut t = vec![0.0f32; h2];
        let mut q = vec![0i8; h2 * h1];
        // |W| and |W − t·q| (the weights' own quantisation error), H₂ × H₁.
        let mut w_abs = vec![0.0f32; h2 * h1];
        let mut dw_abs = vec![0.0f32; h2 * h1];
        for j in 0..h2 {
            let row = &w2v[j * h1..(j + 1) * h1];
            let max = row.iter().fold(0.0f32, |m, w| m.max(w.abs()));
            t[j] = max / 127.0;
            for i in 0..h1 {
                let w = row[i];
                let level = if max > 0.0 {
                    (w / t[j]).round().clamp(-127.0, 127.0)
                } else {
                    0.0
                };
                q[j * h1 + i] = level as i8;
                w_abs[j * h1 + i] = w.abs();
                // Rounded up by a relative 2⁻²² so that it bounds the exact difference.
                dw_abs[j * h1 + i] = (w - t[j] * level).abs() * (1.0 + 2.5e-7) + f32::MIN_POSITIVE;
            }
        }
        let b2v = floats(b2);
        let (mut v_abs, mut v_b2, mut v_t) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        let mut sensitivity = vec![0.0f32; d * 2 * h1];
        for l in 0..d {
            let (c, dw) = sensitivity[l * 2 * h1..(l + 1) * 2 * h1].split_at_mut(h1);
            for j in 0..h2 {
                let v = w3v[l * h2 + j].abs();
                v_abs[l] += v;
                v_b2[l] += v * b2v[j].abs();
                v_t[l] += v * t[j];
                for i in 0..h1 {
                    c[i] += v * w_abs[j * h1 + i];
                    dw[i] += v * dw_abs[j * h1 + i];
                }
            }
        }
        // Sums of non-negative terms, rounded up by a relative margin far above their rounding.
        for x in &mut sensitivity {
            *x *= 1.0 + GAMMA;
        }
        let c_sum = (0..d)
            .map(|l| sensitivity[l * 2 * h1..l * 2 * h1 + h1].iter().sum())
            .collect();
        let sensitivity = Tensor::from_slice(&sensitivity)
            .view([d as i64, 2 * h1 as i64])
            .transpose(0, 1)
            .contiguous();
        let w2 = Tensor::from_slice(&q)
            .view([h2 as i64, h1 as i64])
            .transpose(0, 1)
            .contiguous();
        Self {
            h1,
            h2,
            d,
            w2,
            t,
            b2: b2v,
            w3_t: w3.transpose(0, 1).contiguous(),
            b3: floats(b3),
            sensitivity,
            c_sum,
            v_t,
            v_abs,
            v_b2,
        }
    }

    /// Flip decisions for `rows` rows of first-layer activations (`hidden`), written to `flips`
    /// (rows × D, 1: the bit flips) for every row whose logits are all clear of their bounds.
    /// Returns the other rows, which the caller computes in float32. The quick bound is tried
    /// first, the tight one only for rows it does not settle.
    pub(crate) fn decide(
        &self,
        hidden: &(impl Activations + ?Sized),
        rows: usize,
        flips: &mut [u8],
    ) -> Vec<usize> {
        let screened = self.screen(hidden, rows);
        let d = self.d;
        let open: Vec<usize> = (0..rows)
            .filter(|&r| {
                !settle(
                    &screened.logits[r * d..(r + 1) * d],
                    |l| self.quick_bound(&screened, r, l),
                    &mut flips[r * d..(r + 1) * d],
                )
            })
            .collect();
        let tight = self.tight_bounds(&screened, hidden, &open);
        open.iter()
            .enumerate()
            .filter(|&(j, &r)| {
                !settle(
                    &screened.logits[r * d..(r + 1) * d],
                    |l| tight[j * d + l],
                    &mut flips[r * d..(r + 1) * d],
                )
            })
            .map(|(_, &r)| r)
            .collect()
    }

    /// Quantises, multiplies in integers and finishes in float32.
    fn screen(&self, hidden: &(impl Activations + ?Sized), rows: usize) -> Screened {
        let (h1, h2, d) = (self.h1, self.h2, self.d);
        let mut out = Screened {
            logits: Vec::new(),
            q: vec![0i8; rows * h1],
            scale: vec![0.0; rows],
            qsum: vec![0.0; rows],
            hmax: vec![0.0; rows],
            h2max: vec![0.0; rows],
        };
        let mut x = vec![0.0f32; h1];
        for r in 0..rows {
            hidden.write_row(r, &mut x);
            let max = max_non_negative(&x);
            out.hmax[r] = max;
            if max > 0.0 && max.is_finite() {
                let s = max / 127.0;
                out.scale[r] = s;
                let inverse = 127.0 / max;
                let mut sum = 0i32;
                for (level, &v) in out.q[r * h1..(r + 1) * h1].iter_mut().zip(&x) {
                    *level = nearest_level(v * inverse);
                    sum += i32::from(*level);
                }
                out.qsum[r] = sum as f32;
            }
        }
        // Blocks of `ROW_STEP` rows, their buffers reused: a block's integers and activations
        // stay in cache, and every integer product has one shape (oneDNN compiles a kernel per
        // shape; the last block is padded with rows of zeros).
        let mut padded = Vec::new();
        let mut products = vec![0i32; ROW_STEP * h2];
        let mut h2v = vec![0.0f32; ROW_STEP * h2];
        let mut logits = vec![0.0f32; ROW_STEP * d];
        out.logits.reserve(rows * d);
        for start in (0..rows).step_by(ROW_STEP) {
            let n = ROW_STEP.min(rows - start);
            let q = &out.q[start * h1..(start + n) * h1];
            let q = if n == ROW_STEP {
                q
            } else {
                // The last block only: its rows, then zeros.
                padded.extend_from_slice(q);
                padded.resize(ROW_STEP * h1, 0);
                &padded[..]
            };
            Tensor::from_slice(q)
                .view([ROW_STEP as i64, h1 as i64])
                .internal_int_mm(&self.w2)
                .copy_data(&mut products, ROW_STEP * h2);
            for r in 0..n {
                let s = out.scale[start + r];
                let row = &mut h2v[r * h2..(r + 1) * h2];
                for ((h, &p), (&t, &b)) in row
                    .iter_mut()
                    .zip(&products[r * h2..(r + 1) * h2])
                    .zip(self.t.iter().zip(&self.b2))
                {
                    *h = (s * t * p as f32 + b).max(0.0);
                }
                out.h2max[start + r] = max_non_negative(row);
            }
            Tensor::from_slice(&h2v[..n * h2])
                .view([n as i64, h2 as i64])
                .matmul(&self.w3_t)
                .copy_data(&mut logits, n * d);
            for row in logits[..n * d].chunks(d) {
                out.logits
                    .extend(row.iter().zip(&self.b3).map(|(&x, &b)| x + b));
            }
        }
        out
    }

    /// The margin for float32 rounding of logit `l` of row `r`, given its quantisation bound.
    fn rounding(&self, screened: &Screened, r: usize, l: usize, quantised: f32) -> f32 {
        2.0 * GAMMA
            * (screened.hmax[r] * self.c_sum[l]
                + self.v_b2[l]
                + screened.h2max[r] * self.v_abs[l]
                + quantised
                + self.b3[l].abs())
    }

    /// Bounds from the worst case of each error (half a step): s/2 · (Σ_i C_li + Q · Σ_j |V_lj| t_j).
    /// NaN anywhere makes a bound NaN, and no logit is then clear of it.
    fn quick_bound(&self, screened: &Screened, r: usize, l: usize) -> f32 {
        let half = screened.scale[r] * (0.5 + GAMMA);
        let quantised = half * (self.c_sum[l] + screened.qsum[r] * self.v_t[l]);
        quantised + self.rounding(screened, r, l, quantised)
    }

    /// Bounds from the actual errors of each of `rows` (rows.len() × D):
    /// Σ_i |h_i − s·q_i| C_li + s·q_i Σ_j |V_lj| |δW_ji|.
    fn tight_bounds(
        &self,
        screened: &Screened,
        hidden: &(impl Activations + ?Sized),
        rows: &[usize],
    ) -> Vec<f32> {
        if rows.is_empty() {
            return Vec::new();
        }
        let (h1, d) = (self.h1, self.d);
        // In blocks of `ROW_STEP` rows, their buffers reused (as in `screen`).
        let block = ROW_STEP.min(rows.len());
        let mut errors = vec![0.0f32; block * 2 * h1];
        let mut moved = vec![0.0f32; block * d];
        let mut x = vec![0.0f32; h1];
        let mut bounds = Vec::with_capacity(rows.len() * d);
        for rows in rows.chunks(ROW_STEP) {
            // Per row: |h − s·q| then s·q, both rounded up so that they bound the exact values.
            for (out, &r) in errors.chunks_mut(2 * h1).zip(rows) {
                let s = screened.scale[r];
                let (e, a) = out.split_at_mut(h1);
                hidden.write_row(r, &mut x);
                let q = &screened.q[r * h1..(r + 1) * h1];
                for i in 0..h1 {
                    let level = f32::from(q[i]);
                    e[i] = (x[i] - s * level).abs() * (1.0 + GAMMA);
                    a[i] = s * level * (1.0 + GAMMA);
                }
            }
            let n = rows.len();
            Tensor::from_slice(&errors[..n * 2 * h1])
                .view([n as i64, 2 * h1 as i64])
                .matmul(&self.sensitivity)
                .copy_data(&mut moved, n * d);
            for (moved, &r) in moved.chunks(d).zip(rows) {
                bounds.extend(moved.iter().enumerate().map(|(l, &m)| {
                    // A sum of non-negative terms: reordered, it moves by far less than γ.
                    let quantised = m * (1.0 + GAMMA);
                    quantised + self.rounding(screened, r, l, quantised)
                }));
            }
        }
        bounds
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The logits in f64 arithmetic, written out by hand (an independent path).
    fn logits_f64(
        w2: &[f32],
        b2: &[f32],
        w3: &[f32],
        b3: &[f32],
        h: &[f32],
        dims: (usize, usize, usize),
    ) -> Vec<f64> {
        let (h1, h2, d) = dims;
        let mid: Vec<f64> = (0..h2)
            .map(|j| {
                let a: f64 = (0..h1)
                    .map(|i| f64::from(w2[j * h1 + i]) * f64::from(h[i]))
                    .sum();
                (a + f64::from(b2[j])).max(0.0)
            })
            .collect();
        (0..d)
            .map(|l| {
                (0..h2)
                    .map(|j| f64::from(w3[l * h2 + j]) * mid[j])
                    .sum::<f64>()
                    + f64::from(b3[l])
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Every screened logit lies within its bound of the exact logit, for weights and
        /// activations over several orders of magnitude, sparse activations (after ReLU) included,
        /// in a batch of two blocks (the second padded).
        #[test]
        fn the_bound_holds_against_exact_arithmetic(
            seed in 0u64..1000,
            weight_scale in 0.01f32..10.0,
            activation_scale in 0.001f32..100.0,
            zeros in 0.0f64..0.9,
        ) {
            let (h1, h2, d, rows) = (48usize, 40usize, 7usize, ROW_STEP + 30);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut draw = |n: usize, scale: f32| -> Vec<f32> {
                (0..n).map(|_| rng.random_range(-1.0f32..1.0) * scale).collect()
            };
            let (w2, b2) = (draw(h2 * h1, weight_scale), draw(h2, weight_scale));
            let (w3, b3) = (draw(d * h2, weight_scale), draw(d, weight_scale));
            let hidden: Vec<f32> = draw(rows * h1, activation_scale)
                .into_iter()
                .enumerate()
                .map(|(i, v)| if (i * 7919 % 1000) as f64 / 1000.0 < zeros { 0.0 } else { v.abs() })
                .collect();
            let tensor = |v: &[f32], r: usize, c: usize| Tensor::from_slice(v).view([r as i64, c as i64]);
            let screen = Int8Screen::new(
                &tensor(&w2, h2, h1),
                &Tensor::from_slice(&b2),
                &tensor(&w3, d, h2),
                &Tensor::from_slice(&b3),
            );
            let screened = screen.screen(&hidden[..], rows);
            let mut tightest = 0.0f64;
            for r in 0..rows {
                let exact = logits_f64(&w2, &b2, &w3, &b3, &hidden[r * h1..(r + 1) * h1], (h1, h2, d));
                let tight = screen.tight_bounds(&screened, &hidden[..], &[r]);

                for l in 0..d {
                    let error = (f64::from(screened.logits[r * d + l]) - exact[l]).abs();
                    prop_assert!(error <= f64::from(tight[l]),
                        "row {r} logit {l}: error {error} beyond the tight bound {}", tight[l]);
                    let quick = screen.quick_bound(&screened, r, l);
                    prop_assert!(tight[l] <= quick,
                        "row {r} logit {l}: tight bound {} above the quick one {quick}", tight[l]);
                    tightest = tightest.max(error / f64::from(tight[l]));
                }
            }
            // The bound is a worst case, but not a vacuous one.
            prop_assert!(tightest > 1e-3, "largest error/bound {tightest}");
        }
    }

    /// With every quantisation error of the same sign (activations and weights just below a
    /// half step, all weights positive), the errors add up and reach the bound: it is tight.
    #[test]
    fn the_bound_is_reached_when_every_error_has_the_same_sign() {
        let (h1, h2) = (16usize, 8usize);
        // Activation 0 sets the scale to 1; the others sit 0.49 above a level.
        let hidden: Vec<f32> = (0..h1)
            .map(|i| {
                if i == 0 {
                    127.0
                } else {
                    (i * 7 % 120) as f32 + 0.49
                }
            })
            .collect();
        // Weight 0 of each unit sets its scale to 1/127; the others sit 0.49 steps above a level.
        let w2: Vec<f32> = (0..h2 * h1)
            .map(|n| {
                if n % h1 == 0 {
                    1.0
                } else {
                    ((n * 13 % 100) as f32 + 0.49) / 127.0
                }
            })
            .collect();
        let b2 = vec![1.0f32; h2];
        let w3 = vec![0.5f32; h2];
        let b3 = [0.0f32];
        let tensor =
            |v: &[f32], r: usize, c: usize| Tensor::from_slice(v).view([r as i64, c as i64]);
        let screen = Int8Screen::new(
            &tensor(&w2, h2, h1),
            &Tensor::from_slice(&b2),
            &tensor(&w3, 1, h2),
            &Tensor::from_slice(&b3),
        );
        let screened = screen.screen(&hidden[..], 1);
        let exact = logits_f64(&w2, &b2, &w3, &b3, &hidden, (h1, h2, 1));
        let error = exact[0] - f64::from(screened.logits[0]);
        let bound = f64::from(screen.tight_bounds(&screened, &hidden[..], &[0])[0]);
        assert!(
            error > 0.0 && error <= bound && error > 0.95 * bound,
            "error {error}, bound {bound}"
        );
    }

    /// A row of zeros is exact (only the biases), and a NaN activation decides nothing.
    #[test]
    fn zero_rows_are_exact_and_nan_rows_are_left_to_float32() {
        let w2 = Tensor::from_slice(&[0.5f32, -0.25, 1.0, 2.0]).view([2, 2]);
        let w3 = Tensor::from_slice(&[1.0f32, -1.0]).view([1, 2]);
        let screen = Int8Screen::new(
            &w2,
            &Tensor::from_slice(&[0.5f32, 0.25]),
            &w3,
            &Tensor::from_slice(&[0.1f32]),
        );
        let screened = screen.screen(&[0.0, 0.0][..], 1);
        let bound = screen.quick_bound(&screened, 0, 0);
        // relu(0.5) − relu(0.25) + 0.1 = 0.35
        assert!(
            (screened.logits[0] - 0.35).abs() < 1e-6 && bound < 1e-3,
            "{:?} {bound}",
            screened.logits
        );
        let mut flips = [0u8; 2];
        assert_eq!(
            screen.decide(&[0.0, 0.0, f32::NAN, 1.0][..], 2, &mut flips),
            vec![1]
        );
        assert_eq!(flips[0], 1);
    }
}
