//! Tests that need what a machine may lack are switched on explicitly: the full sweep of every
//! Jaco move on ten seeds (minutes of physics, `tests/jaco.rs`) is built only with
//! `SEADS_TEST_JACO_FULL=1`.

#![allow(clippy::print_stdout)] // a build script talks to cargo on stdout

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(seads_test_jaco_full)");
    println!("cargo:rerun-if-env-changed=SEADS_TEST_JACO_FULL");
    if std::env::var("SEADS_TEST_JACO_FULL").as_deref() == Ok("1") {
        println!("cargo:rustc-cfg=seads_test_jaco_full");
    }
}
