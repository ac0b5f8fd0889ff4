/*
 * An LD_PRELOAD library that makes MKL (inside libtorch) believe it runs on an Intel processor:
 * MKL's vendor check, mkl_serv_intel_cpu_true, answers 1. On an AMD processor this shows whether
 * MKL's choice of kernels by vendor changes a run (docs/RESULTS.md, "Determinism across
 * processors": with the portable kernels it does not).
 *
 *   gcc -shared -fPIC -O2 -o target/mkl_intel_vendor.so scripts/determinism/mkl_intel_vendor.c
 *   LD_PRELOAD=$PWD/target/mkl_intel_vendor.so target/release/seads train \
 *     --config data/golden/config.toml --out target/golden-intel-vendor --quiet
 */
int mkl_serv_intel_cpu_true(void) { return 1; }
