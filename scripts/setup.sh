#!/usr/bin/env bash
# One-time set-up of a fresh machine, idempotent: installs libtorch for tch (PyTorch 2.13.0, the
# version tch 0.26 expects) into .venv inside the repository and links it as .libtorch, where
# .cargo/config.toml points LIBTORCH and the binaries' rpath. Needs python3 (3.9+) with venv and
# pip, and access to PyPI. Outside the repository, only Slurm's Debian packages are installed
# (scripts/slurm/install.sh, as root).
#
# `--cuda` (for a machine with an NVIDIA GPU) also installs the CUDA libraries that libtorch's
# CUDA part needs (cuBLAS, cuDNN, ...: the torch wheel's dependencies, about 3 GB); then
# `cargo build --release -p seads-cli --features cuda` builds a binary that takes `--device cuda`.
set -euo pipefail
cuda=false
case "${1:-}" in
  --cuda) cuda=true ;;
  "") ;;
  *) echo "usage: scripts/setup.sh [--cuda]" >&2; exit 2 ;;
esac

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv="$root/.venv"
link="$root/.libtorch"
torch_version=2.13.0
stamp="$venv/.seads-libtorch-$torch_version"
cuda_stamp="$stamp-cuda"

# Slurm and munge for the Slurm test (root and apt-get only; otherwise the test skips).
bash "$root/scripts/slurm/install.sh"

if [[ -f "$stamp" && -f "$link/lib/libtorch_cpu.so" ]] && { ! $cuda || [[ -f "$cuda_stamp" ]]; }; then
  exit 0
fi

echo "seads setup: installing libtorch (PyTorch $torch_version) into $venv" >&2
python3 -m venv "$venv"
# The wheel brings libtorch (headers and shared libraries); its Python dependencies are not needed.
"$venv/bin/pip" install --quiet --no-deps "torch==$torch_version"
# libtorch_cpu.so links the CUDA runtime and CUPTI even on CPU-only machines.
"$venv/bin/pip" install --quiet --no-warn-conflicts "cuda-toolkit[cudart,cupti]==13.0.3"

# A relative link, so that the checkout can be moved.
torch_dir=$("$venv/bin/python" -c 'import os, sysconfig; print(os.path.relpath(sysconfig.get_paths()["purelib"] + "/torch", "'"$root"'"))')
[[ -f "$root/$torch_dir/lib/libtorch_cpu.so" ]] || { echo "seads setup: the torch wheel has no libtorch_cpu.so" >&2; exit 1; }
ln -sfn "$torch_dir" "$link"
touch "$stamp"
echo "seads setup: libtorch ready at $link" >&2
if $cuda; then
  echo "seads setup: installing the CUDA libraries of PyTorch $torch_version into $venv" >&2
  # The same torch, now with its dependencies: the NVIDIA libraries libtorch_cuda.so finds
  # through its own rpath.
  "$venv/bin/pip" install --quiet --no-warn-conflicts "torch==$torch_version"
  touch "$cuda_stamp"
  echo "seads setup: CUDA libraries ready; build with --features cuda" >&2
fi
