#!/usr/bin/env bash
# Builds the `seads` binary for the GPU test machine (PyTorch 2.11.0 with CUDA 13, no Rust, no
# network; ../shared/gpu/README.md) and puts it, stripped, at gpu/seads in the repository root,
# where the device check (scripts/gpu/check.sh) runs it; and the same without CUDA at
# gpu/seads-cpu, which runs here and there alike.
#
# The workspace uses tch 0.26 / libtorch 2.13; that machine has libtorch 2.11, whose tch release
# is 0.24. So the same source (the working tree: HEAD plus uncommitted changes) is copied into a
# git worktree under target/gpu/src, its tch requirement is set to =0.24.0, and it is built there
# against the torch 2.11.0 wheel's libtorch with the `cuda` feature. The CUDA libraries
# (cuBLAS, cuDNN, …) are not needed here: the link allows them to be missing, and there they come
# with PyTorch's wheel. The first build takes about 15 minutes on two cores, later ones a few.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scratch=$root/target/gpu
src=$scratch/src
mkdir -p "$scratch"

# libtorch 2.11.0 from PyPI (the wheel is CUDA 13; only its headers and libraries are used).
if [[ ! -f $scratch/torch/lib/libtorch_cuda.so ]]; then
  echo "gpu build: fetching the torch 2.11.0 wheel" >&2
  python3 -m pip download --quiet --no-deps --only-binary=:all: torch==2.11.0 -d "$scratch/whl"
  (cd "$scratch" && unzip -q -o whl/torch-2.11.0-*.whl 'torch/lib/*' 'torch/include/*' 'torch/share/*')
fi

# The working tree, as a worktree of HEAD with the uncommitted changes applied.
git -C "$root" worktree remove --force "$src" 2>/dev/null || rm -rf "$src"
git -C "$root" worktree prune
git -C "$root" worktree add --quiet --detach "$src" HEAD
git -C "$root" diff HEAD --binary | git -C "$src" apply --allow-empty
(cd "$root" && git ls-files --others --exclude-standard -z | xargs -0 -r cp --parents -t "$src")
sed -i 's/^tch = "0\.26"$/tch = "=0.24.0"/' "$src/Cargo.toml"
grep -q '^tch = "=0.24.0"$' "$src/Cargo.toml" || { echo "gpu build: no tch line to pin in Cargo.toml" >&2; exit 1; }

# The binary only (build scripts must not get the CUDA link flag: cuda feature, build.rs).
cd "$src"
cargo update --quiet -p tch --precise 0.24.0
LIBTORCH=$scratch/torch CARGO_TARGET_DIR=$scratch/target \
  RUSTFLAGS="-C link-arg=-Wl,--allow-shlib-undefined" \
  cargo build --release -p seads-cli --features cuda
mkdir -p "$root/gpu"
cp "$scratch/target/release/seads" "$root/gpu/seads"
strip "$root/gpu/seads"
# The same source without CUDA: it runs here too, so a run it trains on this processor can be
# compared with the same binary's run on the GPU machine's (data/golden/libtorch-2.11/).
LIBTORCH=$scratch/torch CARGO_TARGET_DIR=$scratch/target \
  RUSTFLAGS="-C link-arg=-Wl,--allow-shlib-undefined" \
  cargo build --release -p seads-cli
cp "$scratch/target/release/seads" "$root/gpu/seads-cpu"
strip "$root/gpu/seads-cpu"
# The fingerprint of the floating-point primitives a run uses (`cargo xtask golden`'s), to name
# the primitives in which the GPU machine's processor parts from data/golden/fingerprint.json.
LIBTORCH=$scratch/torch CARGO_TARGET_DIR=$scratch/target \
  RUSTFLAGS="-C link-arg=-Wl,--allow-shlib-undefined" \
  cargo build --release -p seads-rl --example numerics_fingerprint
cp "$scratch/target/release/examples/numerics_fingerprint" "$root/gpu/numerics_fingerprint"
strip "$root/gpu/numerics_fingerprint"
echo "gpu build: $(du -h "$root/gpu/seads" | cut -f1) at gpu/seads ($(git -C "$root" rev-parse --short HEAD), tch 0.24, libtorch 2.11.0, cuda)" >&2
