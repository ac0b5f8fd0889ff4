#!/usr/bin/env bash
# Installs Slurm and munge from Debian's packages for the Slurm test (about 15 s, 14 MB), when
# run as root on Debian or Ubuntu; otherwise says why not and exits 0 (the test is built only
# with SEADS_TEST_SLURM=1, which CI sets, and then fails without Slurm). Idempotent.
set -euo pipefail
export PATH="$PATH:/usr/sbin:/sbin"
if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null \
  && command -v sbatch >/dev/null; then
  exit 0
fi
if [[ $(id -u) != 0 ]] || ! command -v apt-get >/dev/null; then
  echo "seads setup: not installing Slurm (needs root and apt-get); the Slurm test (SEADS_TEST_SLURM=1) cannot run here" >&2
  exit 0
fi
echo "seads setup: installing Slurm and munge from Debian's packages" >&2
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  slurmctld slurmd slurm-client munge >/dev/null
