//! Reacher3: the Reacher's planar arm with a third link (`<game>-reacher3`). The same reach
//! (0.24 m, three links of 0.08 m), motors, damping, time step and soft limits as the Reacher
//! (`reacher.rs`); the elbow and the wrist are both limited to ±160°.
//!
//! The dynamics are MuJoCo's for this arm (the model is written in
//! `scripts/reference/reacher3_mujoco.py`): the rigid-body terms by recursive Newton–Euler over
//! the three links, Euler steps with implicit joint damping, and the soft joint limits solved
//! exactly as the convex problem MuJoCo's solver minimises, with up to two limits active at once.
//! `tests` check single steps against MuJoCo's own (`data/reference/reacher3/steps.json`).

use std::f64::consts::TAU;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::reacher::{
    BOARD_HALF, DAMPING, GEAR, H, IMP_MAX, SUBSTEPS, TIME_CONST, WRIST_LIMIT, impedance,
    push_at_fingertip, to_board,
};
use crate::{Manipulator, Push, Shape, Touch};

/// Number of links and joints.
const N: usize = 3;

/// One rigid link as MuJoCo compiles the model: its capsule (and the fingertip's sphere on the
/// last), at density 1000.
struct Link {
    /// Joint to the next joint (or to the fingertip), m.
    length: f64,
    /// Mass, kg.
    mass: f64,
    /// Joint to the centre of mass, along the link, m.
    com: f64,
    /// Rotational inertia about the centre of mass, kg·m².
    inertia: f64,
}

/// The three links (`scripts/reference/reacher3_mujoco.py` prints these from MuJoCo's compiled
/// model).
const LINKS: [Link; N] = [
    Link {
        length: 0.08,
        mass: 0.029_321_531_433_504_74,
        com: 0.04,
        inertia: 2.215_870_018_332_001_5e-5,
    },
    Link {
        length: 0.08,
        mass: 0.029_321_531_433_504_74,
        com: 0.04,
        inertia: 2.215_870_018_332_001_5e-5,
    },
    Link {
        length: 0.08,
        mass: 0.027_227_136_331_111_54,
        com: 0.037_692_307_692_307_7,
        inertia: 2.003_450_022_754_659_8e-5,
    },
];

/// MuJoCo's constraint regulariser weights of the limited joints (elbow, wrist): (M⁻¹)ⱼⱼ at
/// q = 0.
const INV_WEIGHT0: [f64; LIMITED] = [43_824.606_405_652_47, 77_803.932_806_861_6];

/// Joint state of the three-link arm: angles q (shoulder, elbow, wrist) and velocities q̇.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Reacher3 {
    /// Joint angles (rad); the shoulder is unlimited and not wrapped.
    pub q: [f64; N],
    /// Joint velocities (rad/s).
    pub qd: [f64; N],
}

type Matrix = [[f64; N]; N];

/// Joint torques that give accelerations `qdd` at `q`, `qd` (recursive Newton–Euler in the
/// plane; no gravity acts in it).
fn inverse_dynamics(q: &[f64; N], qd: &[f64; N], qdd: &[f64; N]) -> [f64; N] {
    // Outwards: each link's direction, angular velocity and acceleration, and the acceleration
    // of its centre of mass.
    let mut frames = [([0.0; 2], 0.0, [0.0; 2]); N];
    let (mut angle, mut w, mut dw) = (0.0, 0.0, 0.0);
    let mut origin = [0.0f64; 2];
    for (i, link) in LINKS.iter().enumerate() {
        angle += q[i];
        w += qd[i];
        dw += qdd[i];
        let (s, c) = f64::sin_cos(angle);
        let (e, n) = ([c, s], [-s, c]);
        let at = |r: f64| {
            [
                origin[0] + dw * r * n[0] - w * w * r * e[0],
                origin[1] + dw * r * n[1] - w * w * r * e[1],
            ]
        };
        frames[i] = (e, dw, at(link.com));
        origin = at(link.length);
    }
    // Inwards: the force each link passes to its parent, and the torque about its joint.
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let mut tau = [0.0; N];
    let (mut force, mut torque) = ([0.0f64; 2], 0.0);
    for i in (0..N).rev() {
        let (link, (e, dw, acc)) = (&LINKS[i], frames[i]);
        let own = [link.mass * acc[0], link.mass * acc[1]];
        let to_com = [link.com * e[0], link.com * e[1]];
        let to_next = [link.length * e[0], link.length * e[1]];
        tau[i] = link.inertia * dw + cross(to_com, own) + torque + cross(to_next, force);
        force = [own[0] + force[0], own[1] + force[1]];
        torque = tau[i];
    }
    tau
}

/// The inverse of a symmetric positive-definite 3×3 matrix (by its adjugate).
fn inverse(m: &Matrix) -> Matrix {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % N, (i + 2) % N);
        let (c0, c1) = ((j + 1) % N, (j + 2) % N);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let mut out = [[0.0; N]; N];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = c(j, i) / det;
        }
    }
    out
}

fn times(m: &Matrix, v: &[f64; N]) -> [f64; N] {
    std::array::from_fn(|i| (0..N).map(|j| m[i][j] * v[j]).sum())
}

/// An active soft limit: the joint, the sign of its Jacobian row, and the row's reference
/// acceleration and regulariser.
#[derive(Clone, Copy, Default)]
struct Limit {
    joint: usize,
    sign: f64,
    a_ref: f64,
    r: f64,
}

/// Joints with a soft limit: the elbow and the wrist.
const LIMITED: usize = N - 1;

/// The limit forces λ ≥ 0 of the active `limits` that minimise ½ λᵀ(A + R)λ − λᵀb, with
/// A = J M⁻¹ Jᵀ and b = a_ref − J a₀: the problem MuJoCo's solver minimises, solved exactly by
/// trying the active sets of its (at most two) rows. The problem is strictly convex, so the one
/// set whose solution satisfies the optimality conditions is the answer.
fn limit_forces(limits: &[Limit], minv: &Matrix, a0: &[f64; N]) -> [f64; LIMITED] {
    let n = limits.len();
    let a = |i: usize, j: usize| {
        let (x, y) = (&limits[i], &limits[j]);
        x.sign * y.sign * minv[x.joint][y.joint] + if i == j { x.r } else { 0.0 }
    };
    let b = |i: usize| limits[i].a_ref - limits[i].sign * a0[limits[i].joint];
    // Every subset of rows held active (bit i: row i), the largest first.
    for set in (0..1usize << n).rev() {
        let active = |i: usize| set >> i & 1 == 1;
        let (mut rows, mut count) = ([0usize; LIMITED], 0);
        for i in (0..n).filter(|&i| active(i)) {
            rows[count] = i;
            count += 1;
        }
        let mut lambda = [0.0; LIMITED];
        match rows[..count] {
            [] => {}
            [i] => lambda[i] = b(i) / a(i, i),
            [i, j] => {
                let det = a(i, i) * a(j, j) - a(i, j) * a(j, i);
                lambda[i] = (a(j, j) * b(i) - a(i, j) * b(j)) / det;
                lambda[j] = (a(i, i) * b(j) - a(j, i) * b(i)) / det;
            }
            _ => unreachable!("at most two limited joints"),
        }
        let optimal = (0..n).all(|i| {
            if active(i) {
                lambda[i] >= 0.0
            } else {
                (0..n).map(|j| a(i, j) * lambda[j]).sum::<f64>() >= b(i)
            }
        });
        if optimal {
            return lambda;
        }
    }
    // Unreachable for a positive-definite problem; NaN states end here and stay NaN.
    [f64::NAN; LIMITED]
}

impl Reacher3 {
    /// One physics step of 0.02 s under controls `u` (clipped to [−1, 1]).
    pub fn physics_step(&mut self, u: [f64; N]) {
        let zero = [0.0; N];
        let columns: [[f64; N]; N] = std::array::from_fn(|j| {
            let mut unit = [0.0; N];
            unit[j] = 1.0;
            inverse_dynamics(&self.q, &zero, &unit)
        });
        let mass: Matrix = std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]));
        let bias = inverse_dynamics(&self.q, &self.qd, &zero);
        let smooth: [f64; N] =
            std::array::from_fn(|i| GEAR * u[i].clamp(-1.0, 1.0) - bias[i] - DAMPING * self.qd[i]);
        let minv = inverse(&mass);
        let a0 = times(&minv, &smooth);

        // The violated limits, at most one per limited joint.
        let (mut limits, mut count) = ([Limit::default(); LIMITED], 0);
        for joint in 1..N {
            let q = self.q[joint];
            let (dist, sign) = if q < -WRIST_LIMIT {
                (q + WRIST_LIMIT, 1.0)
            } else if q > WRIST_LIMIT {
                (WRIST_LIMIT - q, -1.0)
            } else {
                continue;
            };
            let imp = impedance(dist.abs());
            let b = 2.0 / (IMP_MAX * TIME_CONST);
            let k = 1.0 / (IMP_MAX * IMP_MAX * TIME_CONST * TIME_CONST);
            limits[count] = Limit {
                joint,
                sign,
                a_ref: -b * sign * self.qd[joint] - k * imp * dist,
                r: (1.0 - imp) / imp * INV_WEIGHT0[joint - 1],
            };
            count += 1;
        }
        let limits = &limits[..count];
        let mut force = smooth;
        for (limit, lambda) in limits.iter().zip(limit_forces(limits, &minv, &a0)) {
            force[limit.joint] += limit.sign * lambda;
        }

        // Euler with implicit damping: (M + h·D) q̈ = f_smooth + f_constraint.
        let mut damped = mass;
        for (i, row) in damped.iter_mut().enumerate() {
            row[i] += H * DAMPING;
        }
        let qdd = times(&inverse(&damped), &force);
        for ((q, qd), acc) in self.q.iter_mut().zip(&mut self.qd).zip(qdd) {
            *qd += H * acc;
            *q += H * *qd;
        }
    }

    /// The two inner joints and the fingertip in the world plane, m.
    pub fn joints(&self) -> [[f64; 2]; N] {
        let mut angle = 0.0;
        let mut at = [0.0f64; 2];
        std::array::from_fn(|i| {
            angle += self.q[i];
            at = [
                at[0] + LINKS[i].length * angle.cos(),
                at[1] + LINKS[i].length * angle.sin(),
            ];
            at
        })
    }
}

impl Manipulator for Reacher3 {
    fn state_dim(&self) -> usize {
        2 * N
    }

    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (vec![-1.0; N + 1], vec![1.0; N + 1])
    }

    fn default_step_limit(&self) -> usize {
        50
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        // Every joint uniform in [0, 2π), as the Reacher's: the soft limits drive joints that
        // start beyond them back during the first steps.
        self.q = std::array::from_fn(|_| rng.random::<f64>() * TAU);
        self.qd = [0.0; N];
    }

    fn step(
        &mut self,
        action: &[f32],
        _rng: &mut ChaCha8Rng,
        touch: &mut dyn FnMut(Touch) -> Push,
    ) -> bool {
        let u = std::array::from_fn(|i| f64::from(action[i]));
        for _ in 0..SUBSTEPS {
            self.physics_step(u);
        }
        push_at_fingertip(action[N], self.joints()[N - 1], touch);
        self.q.iter().chain(&self.qd).all(|x| x.is_finite())
    }

    fn observe(&self, out: &mut [f32]) {
        for (o, x) in out.iter_mut().zip(self.q.iter().chain(&self.qd)) {
            *o = *x as f32;
        }
    }

    fn restore(&mut self, state: &[f32]) -> Result<(), String> {
        self.q = std::array::from_fn(|i| f64::from(state[i]));
        self.qd = std::array::from_fn(|i| f64::from(state[N + i]));
        Ok(())
    }

    fn end_effector(&self) -> [f64; 2] {
        to_board(self.joints()[N - 1])
    }

    fn draw(&self, shapes: &mut Vec<Shape>, extent: &mut [f64; 4]) {
        let mut from = to_board([0.0, 0.0]);
        shapes.push(Shape::Joint { at: from });
        for (i, joint) in self.joints().into_iter().enumerate() {
            let to = to_board(joint);
            shapes.push(Shape::Segment { from, to });
            shapes.push(if i + 1 < N {
                Shape::Joint { at: to }
            } else {
                Shape::Marker { at: to }
            });
            from = to;
        }
        let reach = LINKS.iter().map(|l| l.length).sum::<f64>() / (2.0 * BOARD_HALF) + 0.05;
        *extent = [0.5 - reach, 0.5 - reach, 0.5 + reach, 0.5 + reach];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every recorded step, free or against one or both limits, lands where MuJoCo's did
    /// (MuJoCo's Newton solver stops at its tolerance; the solution here is exact).
    #[test]
    fn steps_match_mujoco() {
        let starts = crate::reacher::mujoco::check_steps("three_link", |q, qd, u| {
            let mut arm = Reacher3 { q, qd };
            arm.physics_step(u);
            (arm.q, arm.qd)
        });
        // Free steps, one limit and both at once are all covered.
        let mut limited = [0usize; 3];
        for q in &starts {
            limited[(1..N).filter(|&j| q[j].abs() > WRIST_LIMIT).count()] += 1;
        }
        assert!(limited.iter().all(|&n| n >= 20), "{limited:?}");
    }

    /// The mass matrix from recursive Newton–Euler is symmetric with a positive diagonal, and
    /// the inverse inverts it.
    #[test]
    fn the_mass_matrix_is_symmetric_and_positive() {
        for q in [[0.0, 0.0, 0.0], [0.3, 2.0, -1.0], [-1.0, 3.0, 3.0]] {
            let m: Matrix = std::array::from_fn(|j| {
                let mut unit = [0.0; N];
                unit[j] = 1.0;
                inverse_dynamics(&q, &[0.0; N], &unit)
            });
            for i in 0..N {
                assert!(m[i][i] > 0.0);
                for j in 0..N {
                    assert!((m[i][j] - m[j][i]).abs() < 1e-18, "{m:?}");
                }
            }
            let id = times(&inverse(&m), &times(&m, &[1.0, -2.0, 0.5]));
            assert!(
                (id[0] - 1.0).abs() < 1e-9 && (id[1] + 2.0).abs() < 1e-9,
                "{id:?}"
            );
        }
    }

    #[test]
    fn the_fingertip_reaches_the_sum_of_the_links() {
        let arm = Reacher3::default();
        assert!((arm.joints()[N - 1][0] - 0.24).abs() < 1e-12);
        let folded = Reacher3 {
            q: [0.0, std::f64::consts::PI, std::f64::consts::PI],
            qd: [0.0; N],
        };
        assert!((folded.joints()[N - 1][0] - 0.08).abs() < 1e-12);
    }
}
