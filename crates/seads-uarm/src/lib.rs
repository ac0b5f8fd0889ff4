//! The real robot of SEADS (SPEC §7): a uArm Swift Pro serial driver, screen calibration, the
//! tablet board reader and an environment over both, with a simulated twin for tests.
