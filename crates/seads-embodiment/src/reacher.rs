//! Reacher (SPEC §2.3): a planar two-link arm whose fingertip pushes virtually on the board.
//!
//! The dynamics are the closed form of SPEC §2.3.1, which reproduces the reference MuJoCo model
//! (Euler integrator with implicit joint damping, soft wrist limit) to float rounding. No general
//! physics engine is used: there are no contacts, and a generic engine would not reproduce
//! MuJoCo's implicit damping and soft-constraint impedance, which dominate this light arm.

use std::f64::consts::TAU;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::cursor::PUSH_THRESHOLD;
use crate::{Manipulator, Push, Shape, Touch};

/// Physics time step (MuJoCo default), s.
pub(crate) const H: f64 = 0.02;
/// Physics steps per environment step (action repeat).
pub(crate) const SUBSTEPS: usize = 2;
/// Joint damping, N·m·s/rad.
pub(crate) const DAMPING: f64 = 0.01;
/// Motor gear: torque = GEAR · control.
pub(crate) const GEAR: f64 = 0.05;
/// Upper arm length, m.
const L1: f64 = 0.12;
/// Distance wrist → fingertip, m.
const L2: f64 = 0.12;
/// Upper arm inertia about the shoulder, kg·m².
const I1: f64 = 2.1411001e-4;
/// Forearm + fingertip inertia about the wrist, kg·m².
const I2: f64 = 1.8867358e-4;
/// Forearm + fingertip mass, kg.
const M2: f64 = 0.0397935069;
/// Wrist → forearm centre of mass, m.
const C2: f64 = 0.0573684211;
/// Wrist limit ±160°.
pub(crate) const WRIST_LIMIT: f64 = 2.792_526_803_190_927;
/// MuJoCo's constraint regulariser weight: (M⁻¹)₂₂ at q = 0.
const INV_WEIGHT0: f64 = 20740.5487;
/// Soft-limit impedance (solimp 0.9, 0.95, width 0.001, midpoint 0.5, power 2).
const IMP_MIN: f64 = 0.9;
pub(crate) const IMP_MAX: f64 = 0.95;
const IMP_WIDTH: f64 = 0.001;
/// Constraint time constant 0.02 s, raised to 2h by MuJoCo; damping ratio 1.
pub(crate) const TIME_CONST: f64 = 2.0 * H;
/// Half-size of the board, m (the board spans [−0.15, 0.15]²).
pub(crate) const BOARD_HALF: f64 = 0.15;

/// Joint state of the arm: angles q (shoulder, wrist) and velocities q̇.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Reacher {
    /// Joint angles (rad); the shoulder is unlimited and not wrapped.
    pub q: [f64; 2],
    /// Joint velocities (rad/s).
    pub qd: [f64; 2],
}

/// Impedance of the soft limit at violation depth `depth` ≥ 0.
pub(crate) fn impedance(depth: f64) -> f64 {
    let x = depth / IMP_WIDTH;
    if x >= 1.0 {
        return IMP_MAX;
    }
    let y = if x <= 0.5 {
        2.0 * x * x
    } else {
        1.0 - 2.0 * (1.0 - x) * (1.0 - x)
    };
    IMP_MIN + y * (IMP_MAX - IMP_MIN)
}

impl Reacher {
    /// One physics step of 0.02 s under controls `u` (clipped to [−1, 1]).
    pub fn physics_step(&mut self, u: [f64; 2]) {
        let tau = [GEAR * u[0].clamp(-1.0, 1.0), GEAR * u[1].clamp(-1.0, 1.0)];
        let [qd1, qd2] = self.qd;
        let (s2, c2) = self.q[1].sin_cos();
        let m11 = I1 + I2 + M2 * L1 * L1 + 2.0 * M2 * L1 * C2 * c2;
        let m12 = I2 + M2 * L1 * C2 * c2;
        let m22 = I2;
        let eta = M2 * L1 * C2 * s2;
        let bias = [-eta * (2.0 * qd1 * qd2 + qd2 * qd2), eta * qd1 * qd1];
        let fs = [
            tau[0] - bias[0] - DAMPING * qd1,
            tau[1] - bias[1] - DAMPING * qd2,
        ];
        let det = m11 * m22 - m12 * m12;
        let minv22 = m11 / det;
        let a0_wrist = (-m12 * fs[0] + m11 * fs[1]) / det;

        // Soft wrist limit: one inequality constraint on the wrist, J = ±e₂.
        let mut fc_wrist = 0.0;
        let violation = if self.q[1] < -WRIST_LIMIT {
            Some((self.q[1] + WRIST_LIMIT, 1.0))
        } else if self.q[1] > WRIST_LIMIT {
            Some((WRIST_LIMIT - self.q[1], -1.0))
        } else {
            None
        };
        if let Some((dist, j)) = violation {
            let imp = impedance(dist.abs());
            let b = 2.0 / (IMP_MAX * TIME_CONST);
            let k = 1.0 / (IMP_MAX * IMP_MAX * TIME_CONST * TIME_CONST);
            let a_ref = -b * (j * qd2) - k * imp * dist;
            let r = (1.0 - imp) / imp * INV_WEIGHT0;
            let lambda = ((a_ref - j * a0_wrist) / (minv22 + r)).max(0.0);
            fc_wrist = j * lambda;
        }

        // Euler with implicit damping: (M + h·D) q̈ = f_smooth + f_constraint.
        let f = [fs[0], fs[1] + fc_wrist];
        let (a11, a12, a22) = (m11 + H * DAMPING, m12, m22 + H * DAMPING);
        let det_h = a11 * a22 - a12 * a12;
        let qdd = [
            (a22 * f[0] - a12 * f[1]) / det_h,
            (-a12 * f[0] + a11 * f[1]) / det_h,
        ];
        for ((q, qd), acc) in self.q.iter_mut().zip(&mut self.qd).zip(qdd) {
            *qd += H * acc;
            *q += H * *qd;
        }
    }

    /// Elbow and fingertip positions in the world plane, m.
    pub fn links(&self) -> ([f64; 2], [f64; 2]) {
        let (s1, c1) = self.q[0].sin_cos();
        let (s12, c12) = (self.q[0] + self.q[1]).sin_cos();
        let elbow = [L1 * c1, L1 * s1];
        (elbow, [elbow[0] + L2 * c12, elbow[1] + L2 * s12])
    }
}

/// Touches the board under the fingertip `tip` (world plane, m) when the push action `push` is
/// on and the fingertip is over the board (the Reacher's and the Reacher3's push).
pub(crate) fn push_at_fingertip(push: f32, tip: [f64; 2], touch: &mut dyn FnMut(Touch) -> Push) {
    if push > PUSH_THRESHOLD {
        let [u, v] = to_board(tip);
        if (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
            touch(Touch::At { u, v });
        }
    }
}

/// World plane (m) → normalised board coordinates (no flip: row 0 at y ≈ −0.15).
pub(crate) fn to_board(p: [f64; 2]) -> [f64; 2] {
    [
        (p[0] + BOARD_HALF) / (2.0 * BOARD_HALF),
        (p[1] + BOARD_HALF) / (2.0 * BOARD_HALF),
    ]
}

impl Manipulator for Reacher {
    fn state_dim(&self) -> usize {
        4
    }

    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (vec![-1.0; 3], vec![1.0; 3])
    }

    fn default_step_limit(&self) -> usize {
        50
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        // Both joints uniform in [0, 2π): the wrist often starts beyond its limit, and the soft
        // limit drives it back during the first steps, as in the reference.
        self.q = [rng.random::<f64>() * TAU, rng.random::<f64>() * TAU];
        self.qd = [0.0; 2];
    }

    fn step(
        &mut self,
        action: &[f32],
        _rng: &mut ChaCha8Rng,
        touch: &mut dyn FnMut(Touch) -> Push,
    ) -> bool {
        let u = [action[0] as f64, action[1] as f64];
        for _ in 0..SUBSTEPS {
            self.physics_step(u);
        }
        push_at_fingertip(action[2], self.links().1, touch);
        self.q.iter().chain(&self.qd).all(|x| x.is_finite())
    }

    fn observe(&self, out: &mut [f32]) {
        out[0] = self.q[0] as f32;
        out[1] = self.q[1] as f32;
        out[2] = self.qd[0] as f32;
        out[3] = self.qd[1] as f32;
    }

    fn restore(&mut self, state: &[f32]) -> Result<(), String> {
        self.q = [state[0] as f64, state[1] as f64];
        self.qd = [state[2] as f64, state[3] as f64];
        Ok(())
    }

    fn end_effector(&self) -> [f64; 2] {
        to_board(self.links().1)
    }

    fn draw(&self, shapes: &mut Vec<Shape>, extent: &mut [f64; 4]) {
        let (elbow, tip) = self.links();
        let (base, elbow, tip) = (to_board([0.0, 0.0]), to_board(elbow), to_board(tip));
        shapes.push(Shape::Segment {
            from: base,
            to: elbow,
        });
        shapes.push(Shape::Segment {
            from: elbow,
            to: tip,
        });
        shapes.push(Shape::Joint { at: base });
        shapes.push(Shape::Joint { at: elbow });
        shapes.push(Shape::Marker { at: tip });
        let reach = (L1 + L2) / (2.0 * BOARD_HALF) + 0.05;
        *extent = [0.5 - reach, 0.5 - reach, 0.5 + reach, 0.5 + reach];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One physics step from `q`, `qd` under `u`, against values computed by an independent NumPy
    /// transcription of SPEC §2.3.1 with explicit matrices and `linalg.solve`
    /// (`scripts/reference/reacher_step.py` prints them).
    fn check(q: [f64; 2], qd: [f64; 2], u: [f64; 2], q_next: [f64; 2], qd_next: [f64; 2]) {
        let mut arm = Reacher { q, qd };
        arm.physics_step(u);
        for i in 0..2 {
            assert!(
                (arm.q[i] - q_next[i]).abs() < 1e-12,
                "q[{i}] = {} ≠ {}",
                arm.q[i],
                q_next[i]
            );
            assert!(
                (arm.qd[i] - qd_next[i]).abs() < 1e-10,
                "qd[{i}] = {} ≠ {}",
                arm.qd[i],
                qd_next[i]
            );
        }
    }

    #[test]
    fn free_motion_matches_hand_computation() {
        check(
            [0.3, 1.0],
            [0.5, -1.2],
            [0.7, -0.4],
            [0.3225523654003376, 0.9568340999046914],
            [1.1276182700168813, -2.1582950047654323],
        );
        // Controls beyond ±1 are clipped.
        check(
            [0.0, 0.0],
            [0.0, 0.0],
            [2.0, -3.0],
            [0.037342333980211743, -0.0959039400040797],
            [1.8671166990105872, -4.795197000203985],
        );
    }

    #[test]
    fn violated_wrist_limit_matches_hand_computation() {
        // Deep violation (impedance 0.95): the limit pushes the wrist back although the motor
        // drives it outwards.
        check(
            [1.0, 3.0],
            [0.1, 0.5],
            [0.0, 1.0],
            [0.9990999514685305, 2.992524291348141],
            [-0.04500242657347436, -0.37378543259293995],
        );
        // Shallow violation below the impedance width (impedance 0.916).
        check(
            [-0.2, -WRIST_LIMIT - 0.0004],
            [0.0, -0.3],
            [0.5, -1.0],
            [-0.18596017210892762, -2.809363545113862],
            [0.7019913945536199, -0.8218370961467438],
        );
    }

    /// The closed form against MuJoCo itself: single steps of a two-link model with the
    /// Reacher's parameters, free and against the wrist limit, recorded by MuJoCo 4
    /// (`scripts/reference/reacher3_mujoco.py`).
    #[test]
    fn steps_match_mujoco() {
        let starts = mujoco::check_steps("two_link", |q, qd, u| {
            let mut arm = Reacher { q, qd };
            arm.physics_step(u);
            (arm.q, arm.qd)
        });
        let limited = starts.iter().filter(|q| q[1].abs() > WRIST_LIMIT).count();
        assert!(limited >= 50 && starts.len() - limited >= 50, "{limited}");
    }

    #[test]
    fn terminal_speed_is_gear_over_damping() {
        let mut arm = Reacher::default();
        for _ in 0..2000 {
            arm.physics_step([1.0, 1.0]);
        }
        assert!((arm.qd[0] - GEAR / DAMPING).abs() < 1e-6, "{:?}", arm.qd);
        // The wrist rests against its soft limit, slightly beyond it under full torque.
        assert!(
            arm.q[1] > WRIST_LIMIT && arm.q[1] < WRIST_LIMIT + 0.1,
            "{}",
            arm.q[1]
        );
    }

    #[test]
    fn impedance_curve() {
        assert!((impedance(0.0) - 0.9).abs() < 1e-15);
        assert!((impedance(0.0005) - 0.925).abs() < 1e-15);
        assert!((impedance(0.0004) - 0.916).abs() < 1e-12);
        assert_eq!(impedance(0.2), 0.95);
    }
}

/// MuJoCo's own single physics steps of the planar arms (`data/reference/reacher3/steps.json`,
/// written by `scripts/reference/reacher3_mujoco.py`), for the Reacher's and the Reacher3's tests.
#[cfg(test)]
pub(crate) mod mujoco {
    /// Runs `step` from every recorded state of `model` (`two_link`, `three_link`) and checks
    /// that it lands where MuJoCo's step did: angles within 10⁻⁹ rad, velocities within
    /// 10⁻⁷ rad/s (MuJoCo's solver stops at its tolerance). Returns the recorded start angles.
    pub(crate) fn check_steps<const K: usize>(
        model: &str,
        mut step: impl FnMut([f64; K], [f64; K], [f64; K]) -> ([f64; K], [f64; K]),
    ) -> Vec<[f64; K]> {
        let text = include_str!("../../../data/reference/reacher3/steps.json");
        let data: serde_json::Value = serde_json::from_str(text).unwrap();
        let joints =
            |v: &serde_json::Value| -> [f64; K] { std::array::from_fn(|i| v[i].as_f64().unwrap()) };
        let steps = data[model]["steps"].as_array().unwrap();
        assert!(steps.len() >= 100, "{model}: {} steps", steps.len());
        let mut starts = Vec::new();
        for recorded in steps {
            let q0 = joints(&recorded["q"]);
            let (q, qd) = step(q0, joints(&recorded["qd"]), joints(&recorded["u"]));
            let (q_ref, qd_ref) = (joints(&recorded["q_next"]), joints(&recorded["qd_next"]));
            for i in 0..K {
                assert!(
                    (q[i] - q_ref[i]).abs() < 1e-9 && (qd[i] - qd_ref[i]).abs() < 1e-7,
                    "{recorded}: joint {i}: q {} against {}, q̇ {} against {}",
                    q[i],
                    q_ref[i],
                    qd[i],
                    qd_ref[i]
                );
            }
            starts.push(q0);
        }
        starts
    }
}
