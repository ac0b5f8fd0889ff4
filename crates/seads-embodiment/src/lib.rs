//! Embodied environments of SEADS (SPEC §2): a continuous manipulator — Cursor, planar Reacher,
//! Kinova Jaco — in front of a board game, with the ground-truth symbolic mapping Φ(s) = z.
//! Will own the environment trait, the environments, their registry and a batched runner.
