//! Planning with learned skills (SPEC §4): breadth-first search over skill sequences on bit-packed
//! symbolic states through a successor trait, plan execution with and without re-planning.
