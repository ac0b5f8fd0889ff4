#!/usr/bin/env bash
# One-time set-up of a fresh machine, idempotent: installs libtorch for tch (PyTorch 2.13.0, the
# version tch 0.26 expects) once per machine and user, into a virtual environment outside the
# checkout (`$SEADS_LIBTORCH_HOME`, by default `~/.cache/seads`, as
# `torch-2.13.0/`), and links it as `.libtorch` in the repository root, where
# .cargo/config.toml points LIBTORCH and the binaries' rpath. Every clone on the machine (CI's
# fresh clone included) links the same one instead of fetching the 1.2 GB wheel again. Needs
# python3 (3.9+) with venv and pip, and access to PyPI the first time. Outside the repository,
# only that folder and Slurm's Debian packages are written (scripts/slurm/install.sh, as root).
#
# An installation is complete once its stamp file is written, last; one without it (stopped
# midway) is made again. Two set-ups at once take turns (flock).
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
torch_version=2.13.0
store=${SEADS_LIBTORCH_HOME:-${XDG_CACHE_HOME:-$HOME/.cache}/seads}
venv="$store/torch-$torch_version"
link="$root/.libtorch"
stamp="$venv/.seads-libtorch-$torch_version"
cuda_stamp="$stamp-cuda"

# Slurm and munge for the Slurm test (root and apt-get only; the test runs with SEADS_TEST_SLURM=1).
bash "$root/scripts/slurm/install.sh"

# Ready: this version installed and the link pointing into it (a link left by an older version,
# or by the in-repository .venv of earlier set-ups, is made again).
ready() {
  [[ -f "$stamp" && -f "$link/lib/libtorch_cpu.so" ]] && { ! $cuda || [[ -f "$cuda_stamp" ]]; } \
    && [[ "$(readlink -f "$link")" == "$(readlink -f "$venv")"/* ]]
}
ready && exit 0

mkdir -p "$store"
exec 9> "$store/.lock"
flock 9
if [[ ! -f "$stamp" ]]; then
  echo "seads setup: installing libtorch (PyTorch $torch_version) into $venv" >&2
  rm -rf "$venv"
  python3 -m venv "$venv"
  # The wheel brings libtorch (headers and shared libraries); its Python dependencies are not needed.
  "$venv/bin/pip" install --quiet --no-deps "torch==$torch_version"
  # libtorch_cpu.so links the CUDA runtime and CUPTI even on CPU-only machines.
  "$venv/bin/pip" install --quiet --no-warn-conflicts "cuda-toolkit[cudart,cupti]==13.0.3"
  touch "$stamp"
fi
torch_dir=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"] + "/torch")')
[[ -f "$torch_dir/lib/libtorch_cpu.so" ]] || { echo "seads setup: the torch wheel has no libtorch_cpu.so" >&2; exit 1; }
ln -sfn "$torch_dir" "$link"
echo "seads setup: libtorch ready at $link" >&2
if $cuda && [[ ! -f "$cuda_stamp" ]]; then
  echo "seads setup: installing the CUDA libraries of PyTorch $torch_version into $venv" >&2
  # The same torch, now with its dependencies: the NVIDIA libraries libtorch_cuda.so finds
  # through its own rpath.
  "$venv/bin/pip" install --quiet --no-warn-conflicts "torch==$torch_version"
  touch "$cuda_stamp"
  echo "seads setup: CUDA libraries ready; build with --features cuda" >&2
fi
