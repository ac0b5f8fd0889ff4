//! Kinova Jaco (SPEC §2.4): a 6-DOF arm with a 3-finger hand pressing a physical board, simulated
//! with a rapier3d multibody.
//!
//! Reproduced from dm_control's MJCF (`jaco_arm.xml`, `jaco_hand.xml`): body offsets and
//! orientations, joint axes and limits, masses, per-joint armature, damping and friction loss,
//! velocity servos (force = kv·(ctrl − q̇) clamped to the force range), 0.1 s per environment step
//! as 50 physics steps of 2 ms, the 42-value observation, the random tool pose above the board
//! at reset and after every move, and press detection by contact force on the fields.
//!
//! Deviations (documented, all in the interest of a mesh-free model):
//! - Geometry: capsules of similar extent replace the STL meshes; link inertias follow from the
//!   capsules with the MJCF masses. A finger is one capsule (proximal and distal links rigidly
//!   joined, as in the MJCF where the distal link has no joint).
//! - Robot parts collide with the board and the floor, not with each other; the reset rejects
//!   poses whose robot geometry comes below the highest field top instead of testing arm–arm
//!   collisions.
//! - Joint limits are rapier's hard limits (MuJoCo's are soft); the fingers start at their lower
//!   limit 0.15 rad instead of 0.
//! - The "torque" observation is the servo torque clamp(kv·(ctrl − q̇)) after the step (MuJoCo's
//!   torque sensors also include the load carried by each joint).
//! - The reset IK is rapier's damped least squares on the whole pose (rotation weight 1, the
//!   reference uses 2); velocities are zeroed when the arm is re-initialised after a move.
//! - Presses are detected from the contacts of the physics step just taken (the reference reads
//!   the contacts cached before the substep).

// The MJCF's rounded quaternion literals (0.707107, 0.866025) are kept as written there.
#![allow(clippy::approx_constant)]

use std::f32::consts::{PI, TAU};
use std::num::NonZeroUsize;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{Manipulator, Push, Shape, Touch};

/// Physics steps per environment step in the reference (0.1 s control period / 2 ms).
pub const DEFAULT_SUBSTEPS: usize = 50;

/// The Jaco's own options (`[env_config.manipulator]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JacoOptions {
    /// Physics steps per 0.1 s environment step (reference: [`DEFAULT_SUBSTEPS`] steps of 2 ms).
    /// Fewer steps run proportionally faster with coarser contact and servo dynamics.
    pub physics_substeps: NonZeroUsize,
}

impl Default for JacoOptions {
    fn default() -> Self {
        Self {
            physics_substeps: NonZeroUsize::new(DEFAULT_SUBSTEPS).expect("50 is not zero"),
        }
    }
}
/// Control period, s.
const CONTROL_DT: f32 = 0.1;
/// Velocity-solver iterations of rapier per physics step (the multibody mass matrix dominates
/// the cost; one iteration tracks the servos as closely as four on this arm).
const SOLVER_ITERATIONS: usize = 1;
/// Where the arm's base stands: beyond the top edge of the board.
const BASE: [f32; 3] = [0.0, 0.4, 0.0];
/// Touch sensor threshold, N.
const TOUCH_THRESHOLD: f32 = 1e-3;
/// Half-width of a board field, m.
const FIELD_HALF: f32 = 0.05;
/// Half-width of a LightsOut field's touch sensor (70 % of the field), m.
const SENSOR_HALF: f32 = 0.035;
/// Half-height of a touch sensor volume, m.
const SENSOR_DEPTH: f32 = 0.005;
/// Grip site (tool centre point) in the hand frame.
const GRIP_SITE: [f32; 3] = [0.0, -0.0001, -0.159];
/// Pinch site in the hand frame; its orientation is the quaternion (w, x, y, z) below.
const PINCH_SITE: [f32; 3] = [0.015, 0.0024, -0.193];
const SITE_QUAT: [f32; 4] = [0.0, 0.707_106_78, 0.707_106_78, 0.0];

/// One jointed body of the robot, in MJCF terms.
struct LinkDef {
    /// Offset from the parent body, in the parent frame.
    pos: [f32; 3],
    /// Orientation relative to the parent (w, x, y, z).
    quat: [f32; 4],
    /// Index of the parent in `LINKS` (`None`: the fixed base).
    parent: Option<usize>,
    mass: f32,
    /// Collision capsule `(a, b, radius)` in the body frame.
    capsule: ([f32; 3], [f32; 3], f32),
    /// Joint range (rad), `None` if unlimited.
    range: Option<[f32; 2]>,
    armature: f32,
    damping: f32,
    friction_loss: f32,
    /// Velocity servo gain and the control and force ranges (symmetric).
    kv: f32,
    ctrl: f32,
    force: f32,
}

const LARGE: (f32, f32, f32, f32) = (4.0, 2.0, 0.62832, 30.5); // armature, friction, ctrl, force
const SMALL: (f32, f32, f32, f32) = (2.0, 1.0, 0.83776, 6.8);
const FINGER_CAPSULE: ([f32; 3], [f32; 3], f32) = ([0.0, 0.0, 0.0], [0.08, -0.005, 0.0], 0.01);
const FINGER_MASS: f32 = 0.0255204 + 0.0132655;

const fn arm(
    pos: [f32; 3],
    quat: [f32; 4],
    parent: Option<usize>,
    mass: f32,
    capsule: ([f32; 3], [f32; 3], f32),
    range: Option<[f32; 2]>,
    j: (f32, f32, f32, f32),
) -> LinkDef {
    LinkDef {
        pos,
        quat,
        parent,
        mass,
        capsule,
        range,
        armature: j.0,
        damping: 0.01,
        friction_loss: j.1,
        kv: 500.0,
        ctrl: j.2,
        force: j.3,
    }
}

const fn finger(pos: [f32; 3], quat: [f32; 4]) -> LinkDef {
    LinkDef {
        pos,
        quat,
        parent: Some(5),
        mass: FINGER_MASS,
        capsule: FINGER_CAPSULE,
        range: Some([0.15, 1.35]),
        armature: 0.1,
        damping: 0.75,
        friction_loss: 0.1,
        kv: 10.0,
        ctrl: 5.0,
        force: 1.0,
    }
}

/// Arm joints 1–6 (b_1 … b_6, the hand is rigidly part of b_6), then fingers 1–3.
const LINKS: [LinkDef; 9] = [
    arm(
        [0.0, 0.0, 0.15675],
        [0.0, 0.0, 1.0, 0.0],
        None,
        0.643205,
        ([0.0, 0.0, -0.02], [0.0, 0.0016, -0.11875], 0.045),
        None,
        LARGE,
    ),
    arm(
        [0.0, 0.0016, -0.11875],
        [0.0, 0.0, -0.707107, 0.707107],
        Some(0),
        1.16915,
        ([0.0, 0.0, 0.0], [0.0, -0.41, 0.0], 0.04),
        Some([0.820305, 5.462881]),
        LARGE,
    ),
    arm(
        [0.0, -0.41, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        Some(1),
        0.673443,
        ([0.0, 0.0, 0.0], [0.0, 0.2073, -0.0114], 0.035),
        Some([0.331613, 5.951573]),
        LARGE,
    ),
    arm(
        [0.0, 0.2073, -0.0114],
        [0.0, 0.0, -0.707107, 0.707107],
        Some(2),
        0.221432,
        ([0.0, 0.0, 0.0], [0.0, -0.03703, -0.06414], 0.03),
        None,
        SMALL,
    ),
    arm(
        [0.0, -0.03703, -0.06414],
        [0.0, 0.0, 0.5, 0.866025],
        Some(3),
        0.221432,
        ([0.0, 0.0, 0.0], [0.0, -0.03703, -0.06414], 0.03),
        None,
        SMALL,
    ),
    // b_6 carries the hand (0.54719 kg): the wrist site and the hand's own orientation cancel.
    arm(
        [0.0, -0.03703, -0.06414],
        [0.0, 0.0, 0.5, 0.866025],
        Some(4),
        0.54719,
        ([0.0, 0.0, -0.02], [0.0, 0.0, -0.1], 0.04),
        None,
        SMALL,
    ),
    finger(
        [0.00279, 0.03126, -0.11467],
        [0.24396, -0.63159, -0.38818, 0.62521],
    ),
    finger(
        [-0.02226, -0.02707, -0.11482],
        [0.601679, -0.254671, 0.659653, -0.37146],
    ),
    finger(
        [0.02226, -0.02707, -0.11482],
        [0.659653, -0.37146, 0.601679, -0.254671],
    ),
];

/// Index of the hand body (b_6) in `LINKS`.
const HAND: usize = 5;

fn quat(wxyz: [f32; 4]) -> Rotation {
    Rotation::from_xyzw(wxyz[1], wxyz[2], wxyz[3], wxyz[0]).normalize()
}

fn vec3(v: [f32; 3]) -> Vector {
    Vector::new(v[0], v[1], v[2])
}

/// Which board the Jaco plays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacoBoard {
    /// LightsOut 5×5; `stairs` raises the fields by their distance from the centre
    /// (LightsOut3DJaco).
    LightsOut {
        /// The 3-D variant.
        stairs: bool,
    },
    /// TileSwap 3×3.
    TileSwap,
}

impl JacoBoard {
    fn side(self) -> usize {
        match self {
            JacoBoard::LightsOut { .. } => 5,
            JacoBoard::TileSwap => 3,
        }
    }

    /// Half-height of field (row, col).
    fn field_half_height(self, row: usize, col: usize) -> f32 {
        match self {
            JacoBoard::LightsOut { stairs: true } => match row.abs_diff(2).max(col.abs_diff(2)) {
                0 => 0.01,
                1 => 0.03,
                _ => 0.05,
            },
            _ => 0.01,
        }
    }

    /// Half-width of the whole board, m.
    fn half_width(self) -> f32 {
        self.side() as f32 * FIELD_HALF
    }
}

/// The Jaco arm and hand in front of a physical board.
pub struct Jaco {
    board: JacoBoard,
    world: PhysicsWorld,
    /// Rigid bodies of `LINKS`, in order.
    bodies: Vec<RigidBodyHandle>,
    /// Field colliders, row-major, with their top height.
    fields: Vec<(ColliderHandle, f32)>,
    /// Every robot collider: the base first, then one per link of `LINKS`.
    robot: Vec<ColliderHandle>,
    /// Controls of the last action, mapped to the servo ranges.
    ctrl: [f32; 9],
    /// Physics steps per environment step.
    substeps: usize,
    /// Resets and re-initialisations that found no reachable pose and fell back to a fixed one.
    ik_fallbacks: u64,
    /// Where the arm touched the board (board coordinates) for the last step's move, before it
    /// was re-initialised; `None` after a step without a move.
    move_point: Option<[f64; 2]>,
}

impl Jaco {
    /// How many initial poses (resets, and re-initialisations after a move) found no reachable
    /// pose by inverse kinematics and used the fixed fallback pose, since this arm was built.
    pub fn ik_fallbacks(&self) -> u64 {
        self.ik_fallbacks
    }

    /// A Jaco in front of `board` simulated with `substeps` physics steps per 0.1 s environment
    /// step ([`DEFAULT_SUBSTEPS`] as the reference), in a fixed pose until the first reset.
    pub fn new(board: JacoBoard, substeps: usize) -> Self {
        let substeps = substeps.max(1);
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -9.81);
        world.integration_parameters.dt = CONTROL_DT / substeps as f32;
        world.integration_parameters.num_solver_iterations = SOLVER_ITERATIONS;
        let static_groups =
            InteractionGroups::new(Group::GROUP_2, Group::GROUP_1, InteractionTestMode::And);
        let robot_groups =
            InteractionGroups::new(Group::GROUP_1, Group::GROUP_2, InteractionTestMode::And);
        // Floor (top at z = 0) and board fields (boxes standing on the floor).
        world.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, 0.0, -0.05)),
            ColliderBuilder::cuboid(1.0, 1.0, 0.05)
                .friction(0.4)
                .collision_groups(static_groups),
        );
        let n = board.side();
        let mut fields = Vec::with_capacity(n * n);
        for row in 0..n {
            for col in 0..n {
                let h = board.field_half_height(row, col);
                let centre = Vector::new(
                    (col as f32 - (n - 1) as f32 / 2.0) * 2.0 * FIELD_HALF,
                    ((n - 1) as f32 / 2.0 - row as f32) * 2.0 * FIELD_HALF,
                    h,
                );
                let (_, c) = world.insert(
                    RigidBodyBuilder::fixed().translation(centre),
                    ColliderBuilder::cuboid(FIELD_HALF, FIELD_HALF, h)
                        .collision_groups(static_groups),
                );
                fields.push((c, 2.0 * h));
            }
        }
        // The robot: a fixed base and a multibody chain with the hand's fingers.
        let (base, base_collider) = world.insert(
            RigidBodyBuilder::fixed().translation(vec3(BASE)),
            ColliderBuilder::capsule_z(0.055, 0.045)
                .translation(Vector::new(0.0, 0.0, 0.075))
                .collision_groups(robot_groups),
        );
        let mut robot = vec![base_collider];
        let mut bodies: Vec<RigidBodyHandle> = Vec::with_capacity(LINKS.len());
        let mut poses: Vec<Pose> = Vec::with_capacity(LINKS.len());
        let base_pose = Pose::from_translation(vec3(BASE));
        // The hinge is the joint frame's x axis: map x to the body's z axis.
        let x_to_z = Rotation::from_rotation_arc(Vector::X, Vector::Z);
        for def in &LINKS {
            let (parent_handle, parent_pose) = match def.parent {
                None => (base, base_pose),
                Some(p) => (bodies[p], poses[p]),
            };
            let local = Pose::from_parts(vec3(def.pos), quat(def.quat));
            let pose = parent_pose * local;
            let (a, b, r) = def.capsule;
            let (handle, collider) = world.insert(
                RigidBodyBuilder::dynamic().pose(pose).can_sleep(false),
                ColliderBuilder::capsule_from_endpoints(vec3(a), vec3(b), r)
                    .mass(def.mass)
                    .collision_groups(robot_groups),
            );
            robot.push(collider);
            let mut joint = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                .local_frame1(Pose::from_parts(vec3(def.pos), quat(def.quat) * x_to_z))
                .local_frame2(Pose::from_parts(Vector::ZERO, x_to_z))
                .motor_model(JointAxis::AngX, MotorModel::ForceBased)
                .motor_velocity(JointAxis::AngX, 0.0, def.kv)
                .motor_max_force(JointAxis::AngX, def.force)
                .contacts_enabled(false);
            if let Some(range) = def.range {
                joint = joint.limits(JointAxis::AngX, range);
            }
            world
                .insert_multibody_joint(parent_handle, handle, joint.build())
                .expect("a tree of joints");
            bodies.push(handle);
            poses.push(pose);
        }
        let mut jaco = Self {
            board,
            world,
            bodies,
            fields,
            robot,
            ctrl: [0.0; 9],
            substeps,
            ik_fallbacks: 0,
            move_point: None,
        };
        let dofs: Vec<usize> = (0..LINKS.len()).map(|i| jaco.dof(i)).collect();
        let mb = jaco.multibody_mut();
        for (def, &d) in LINKS.iter().zip(&dofs) {
            mb.armature_mut()[d] = def.armature;
            mb.damping_mut()[d] = def.damping;
            mb.frictions_mut()[d] = def.friction_loss;
        }
        jaco.set_joints(&[0.0, 3.0, 1.0, 0.0, 0.0, 0.0, 0.15, 0.15, 0.15]);
        jaco
    }

    fn multibody(&self) -> &Multibody {
        let link = self
            .world
            .multibody_joints
            .rigid_body_link(self.bodies[0])
            .expect("arm link");
        self.world
            .multibody_joints
            .get_multibody(link.multibody)
            .expect("arm multibody")
    }

    fn multibody_mut(&mut self) -> &mut Multibody {
        let link = *self
            .world
            .multibody_joints
            .rigid_body_link(self.bodies[0])
            .expect("arm link");
        self.world
            .multibody_joints
            .get_multibody_mut(link.multibody)
            .expect("arm multibody")
    }

    /// Degree-of-freedom index of each link, in `LINKS` order.
    fn dof(&self, i: usize) -> usize {
        let link = self
            .world
            .multibody_joints
            .rigid_body_link(self.bodies[i])
            .expect("arm link");
        self.multibody().link(link.id).expect("link").assembly_id()
    }

    /// Joint angles and velocities, in `LINKS` order.
    pub fn joints(&self) -> ([f32; 9], [f32; 9]) {
        let mb = self.multibody();
        let mut q = [0.0; 9];
        let mut qd = [0.0; 9];
        for (i, h) in self.bodies.iter().enumerate() {
            let link_id = self
                .world
                .multibody_joints
                .rigid_body_link(*h)
                .expect("arm link")
                .id;
            let link = mb.link(link_id).expect("link");
            q[i] = link.joint().coords()[3];
            qd[i] = mb.generalized_velocity()[link.assembly_id()];
        }
        (q, qd)
    }

    /// Puts the joints at `q` (in `LINKS` order) at rest and updates every body pose.
    /// Puts the arm at rest at joint positions `q` (6 arm joints, 3 fingers, radians), e.g. a
    /// state recorded from the reference simulation; the servo commands stay as they are.
    pub fn set_joint_positions(&mut self, q: &[f32; 9]) {
        self.set_joints(q);
    }

    fn set_joints(&mut self, q: &[f32; 9]) {
        let (current, _) = self.joints();
        let dofs: Vec<usize> = (0..LINKS.len()).map(|i| self.dof(i)).collect();
        // The root of the multibody (the fixed base) has its own, unused degrees of freedom.
        let mut disp = vec![0.0; self.multibody().ndofs()];
        for i in 0..LINKS.len() {
            disp[dofs[i]] = q[i] - current[i];
        }
        let link = *self
            .world
            .multibody_joints
            .rigid_body_link(self.bodies[0])
            .expect("arm link");
        let mb = self
            .world
            .multibody_joints
            .get_multibody_mut(link.multibody)
            .expect("arm multibody");
        mb.apply_displacements(&disp);
        mb.generalized_velocity_mut().fill(0.0);
        mb.forward_kinematics(&self.world.bodies, true);
        mb.update_rigid_bodies(&mut self.world.bodies, false);
        for &h in &self.bodies {
            let body = &mut self.world.bodies[h];
            body.set_linvel(Vector::ZERO, true);
            body.set_angvel(Vector::ZERO, true);
        }
        // Colliders follow their bodies.
        for &c in &self.robot {
            if let Some(parent) = self.world.colliders[c].parent() {
                let pose = *self.world.bodies[parent].position()
                    * *self.world.colliders[c]
                        .position_wrt_parent()
                        .expect("attached");
                self.world.colliders[c].set_position(pose);
            }
        }
    }

    /// World pose of the hand (b_6).
    fn hand_pose(&self) -> Pose {
        *self.world.bodies[self.bodies[HAND]].position()
    }

    /// World position of the grip site (tool centre point).
    pub fn tcp(&self) -> [f32; 3] {
        self.hand_pose().transform_point(vec3(GRIP_SITE)).to_array()
    }

    /// Lowest point of the robot's geometry.
    fn lowest_point(&self) -> f32 {
        self.robot[1..]
            .iter()
            .map(|&c| {
                let col = &self.world.colliders[c];
                col.shape().compute_aabb(col.position()).mins.z
            })
            .fold(f32::INFINITY, f32::min)
    }

    /// Samples a tool pose in the box above the board, pointing down with a random yaw, and
    /// reaches it by IK from random joint configurations (SPEC §2.4 reset).
    fn randomize(&mut self, rng: &mut ChaCha8Rng) {
        let highest_field = self.fields.iter().map(|f| f.1).fold(0.0, f32::max);
        for _pose in 0..10 {
            let tcp = Vector::new(
                rng.random_range(-0.1..=0.1),
                rng.random_range(-0.1..=0.1),
                rng.random_range(0.2..=0.4),
            );
            let yaw = rng.random_range(-PI..PI);
            // "Pointing down" grip site = hand frame yawed about z (the site's orientation in the
            // hand equals the reference's pointing-down quaternion).
            let hand_rot = Rotation::from_rotation_z(yaw);
            let target = Pose::from_parts(tcp - hand_rot * vec3(GRIP_SITE), hand_rot);
            for _attempt in 0..10 {
                let mut q = [0.15f32; 9];
                for (i, def) in LINKS.iter().enumerate().take(6) {
                    q[i] = match def.range {
                        Some([lo, hi]) => rng.random_range(lo..=hi),
                        None => rng.random_range(0.0..TAU),
                    };
                }
                self.set_joints(&q);
                if let Some(solution) = self.solve_ik(&target) {
                    self.set_joints(&solution);
                    let error = (self.hand_pose().translation - target.translation).length();
                    if error < 0.01 && self.lowest_point() > highest_field + 0.005 {
                        return;
                    }
                }
            }
        }
        // No pose found (rare; counted, see `ik_fallbacks`): a fixed pose above the board centre.
        self.ik_fallbacks += 1;
        self.set_joints(&[0.0, 3.0, 1.0, 0.0, 0.0, 0.0, 0.15, 0.15, 0.15]);
    }

    /// Joint angles reaching `target` for the hand, wrapped into the joint ranges; `None` if a
    /// limited joint ends outside its range.
    fn solve_ik(&mut self, target: &Pose) -> Option<[f32; 9]> {
        let link_id = self
            .world
            .multibody_joints
            .rigid_body_link(self.bodies[HAND])
            .expect("hand link")
            .id;
        let options = InverseKinematicsOption {
            damping: 0.05,
            max_iters: 60,
            epsilon_linear: 1e-4,
            epsilon_angular: 1e-3,
            ..Default::default()
        };
        let mut disp = DVector::zeros(self.multibody().ndofs());
        self.multibody().inverse_kinematics(
            &self.world.bodies,
            link_id,
            &options,
            target,
            |_| true,
            &mut disp,
        );
        let (mut q, _) = self.joints();
        for i in 0..6 {
            let wrapped = (q[i] + disp[self.dof(i)]).rem_euclid(TAU);
            q[i] = match LINKS[i].range {
                Some([lo, hi]) if !(lo..=hi).contains(&wrapped) => return None,
                _ => wrapped,
            };
        }
        Some(q)
    }

    /// Sets the servo targets from an action in [−1, 1]⁹.
    fn set_controls(&mut self, action: &[f32]) {
        let handles = self.bodies.clone();
        for (i, (&a, def)) in action.iter().zip(&LINKS).enumerate() {
            let ctrl = -def.ctrl + (a.clamp(-1.0, 1.0) + 1.0) / 2.0 * 2.0 * def.ctrl;
            self.ctrl[i] = ctrl;
            let link = *self
                .world
                .multibody_joints
                .rigid_body_link(handles[i])
                .expect("arm link");
            let mb = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
                .expect("arm multibody");
            mb.link_mut(link.id)
                .expect("link")
                .joint
                .data
                .set_motor_velocity(JointAxis::AngX, ctrl, def.kv);
        }
    }

    /// The press of this physics step, if any: LightsOut the field with the largest force inside
    /// its sensor, TileSwap the first contact on the board (as normalised board coordinates);
    /// with the point where it was touched (normalised board coordinates: the first contact on
    /// that field, or on the board), which the reference marks as the skill's contact.
    fn detect_press(&self) -> Option<(Touch, [f64; 2])> {
        // (field, force, its first contact)
        let mut best: Option<(usize, f32, Vector)> = None;
        let mut first_on_board: Option<Vector> = None;
        for (index, &(field, top)) in self.fields.iter().enumerate() {
            let centre = self.world.colliders[field].position().translation;
            let mut force = 0.0;
            let mut first: Option<Vector> = None;
            for pair in self.world.contact_pairs_with(field) {
                let PairContacts::Rigid(contacts) = &pair.contacts else {
                    continue;
                };
                let pos1 = *self.world.colliders[pair.collider1].position();
                for manifold in contacts.solver_manifolds() {
                    for point in &manifold.points {
                        if point.data.impulse <= 0.0 {
                            continue;
                        }
                        let p = pos1.transform_point(point.local_p1);
                        let half = match self.board {
                            JacoBoard::LightsOut { .. } => SENSOR_HALF,
                            JacoBoard::TileSwap => self.board.half_width(),
                        };
                        let sensor_centre = match self.board {
                            JacoBoard::LightsOut { .. } => centre,
                            JacoBoard::TileSwap => Vector::ZERO,
                        };
                        if (p.x - sensor_centre.x).abs() <= half
                            && (p.y - sensor_centre.y).abs() <= half
                            && (p.z - top).abs() <= SENSOR_DEPTH
                        {
                            force += point.data.impulse / self.world.integration_parameters.dt;
                            first.get_or_insert(p);
                            first_on_board.get_or_insert(p);
                        }
                    }
                }
            }
            if let Some(p) = first
                && force > TOUCH_THRESHOLD
                && best.is_none_or(|(_, f, _)| force > f)
            {
                best = Some((index, force, p));
            }
        }
        let (index, _, at_field) = best?;
        match self.board {
            JacoBoard::LightsOut { .. } => {
                Some((Touch::Field(index), self.board_coordinates(at_field)))
            }
            JacoBoard::TileSwap => {
                let [u, v] = self.board_coordinates(first_on_board?);
                Some((Touch::At { u, v }, [u, v]))
            }
        }
    }

    /// A world point in normalised board coordinates (u to the right, v down the rows).
    fn board_coordinates(&self, p: Vector) -> [f64; 2] {
        let w = 2.0 * self.board.half_width();
        [
            ((p.x + w / 2.0) / w) as f64,
            (1.0 - (p.y + w / 2.0) / w) as f64,
        ]
    }
}

impl Clone for Jaco {
    /// Rebuilds the world and copies the joint state and controls (rapier's world is not `Clone`).
    fn clone(&self) -> Self {
        let mut copy = Jaco::new(self.board, self.substeps);
        let (q, qd) = self.joints();
        copy.set_joints(&q);
        let dofs: Vec<usize> = (0..LINKS.len()).map(|i| copy.dof(i)).collect();
        let mb = copy.multibody_mut();
        for i in 0..LINKS.len() {
            mb.generalized_velocity_mut()[dofs[i]] = qd[i];
        }
        let ctrl = self.ctrl;
        let action: Vec<f32> = ctrl.iter().zip(&LINKS).map(|(c, d)| c / d.ctrl).collect();
        copy.set_controls(&action);
        copy.ik_fallbacks = self.ik_fallbacks;
        copy.move_point = self.move_point;
        copy
    }
}

fn symlog1p(x: f32) -> f32 {
    x.signum() * x.abs().ln_1p()
}

impl Manipulator for Jaco {
    fn state_dim(&self) -> usize {
        42
    }

    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (vec![-1.0; 9], vec![1.0; 9])
    }

    fn default_step_limit(&self) -> usize {
        50
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        // A fresh world: rapier keeps contacts and solver warm starts from the previous step,
        // and a reset must depend on nothing but the seed (a resumed run has a fresh world).
        let fallbacks = self.ik_fallbacks;
        *self = Jaco::new(self.board, self.substeps);
        self.ik_fallbacks = fallbacks;
        self.randomize(rng);
        self.set_controls(&[0.0; 9]);
    }

    fn step(
        &mut self,
        action: &[f32],
        rng: &mut ChaCha8Rng,
        touch: &mut dyn FnMut(Touch) -> Push,
    ) -> bool {
        self.set_controls(action);
        self.move_point = None;
        for _ in 0..self.substeps {
            self.world.step();
            if self.move_point.is_none()
                && let Some((press, at)) = self.detect_press()
                && matches!(touch(press), Push::Move(_))
            {
                // After a move the arm is re-initialised; the remaining substeps continue.
                self.move_point = Some(at);
                self.randomize(rng);
            }
        }
        let (q, qd) = self.joints();
        q.iter().chain(&qd).all(|v| v.is_finite()) && self.tcp().iter().all(|v| v.is_finite())
    }

    fn observe(&self, out: &mut [f32]) {
        let (q, qd) = self.joints();
        for j in 0..6 {
            out[2 * j] = q[j].sin();
            out[2 * j + 1] = q[j].cos();
            let torque =
                (LINKS[j].kv * (self.ctrl[j] - qd[j])).clamp(-LINKS[j].force, LINKS[j].force);
            out[12 + j] = symlog1p(torque);
            out[18 + j] = qd[j];
        }
        out[24..27].copy_from_slice(&q[6..9]);
        out[27..30].copy_from_slice(&qd[6..9]);
        let hand = self.hand_pose();
        out[30..33].copy_from_slice(&hand.transform_point(vec3(PINCH_SITE)).to_array());
        let rot = rapier3d::math::Matrix::from_quat(hand.rotation * quat(SITE_QUAT));
        for r in 0..3 {
            for c in 0..3 {
                out[33 + 3 * r + c] = rot.col(c)[r];
            }
        }
    }

    fn restore(&mut self, _state: &[f32]) -> Result<(), String> {
        Err("the Jaco observation does not determine its state".into())
    }

    fn can_restore(&self) -> bool {
        false
    }

    fn move_point(&self) -> Option<[f64; 2]> {
        self.move_point
    }

    fn end_effector(&self) -> [f64; 2] {
        self.board_coordinates(vec3(self.tcp()))
    }

    fn field_heights(&self) -> Vec<f64> {
        self.fields.iter().map(|&(_, top)| f64::from(top)).collect()
    }

    fn draw(&self, shapes: &mut Vec<Shape>, extent: &mut [f64; 4]) {
        // Top view: links projected on the board plane, board coordinates with the y flip.
        let to_board = |p: Vector| self.board_coordinates(p);
        let mut points = vec![to_board(vec3(BASE))];
        for &h in &self.bodies[..=HAND] {
            points.push(to_board(self.world.bodies[h].position().translation));
        }
        points.push(to_board(vec3(self.tcp())));
        for pair in points.windows(2) {
            shapes.push(Shape::Segment {
                from: pair[0],
                to: pair[1],
            });
        }
        for &p in &points[..points.len() - 1] {
            shapes.push(Shape::Joint { at: p });
        }
        shapes.push(Shape::Marker {
            at: *points.last().expect("tcp"),
        });
        for p in &points {
            extent[0] = extent[0].min(p[0] - 0.05);
            extent[1] = extent[1].min(p[1] - 0.05);
            extent[2] = extent[2].max(p[0] + 0.05);
            extent[3] = extent[3].max(p[1] + 0.05);
        }
    }
}
