#!/usr/bin/env bash
# Starts a private single-node Slurm cluster (munged, slurmctld, slurmd; Debian's packages, no
# systemd) with its configuration, key, sockets, state and logs all under DIR, for the
# project's Slurm test (crates/seads-cli/tests/end_to_end/slurm.rs). Waits until the node is idle, then
# prints `export SLURM_CONF=DIR/etc/slurm.conf`.
#
#   scripts/slurm/start.sh DIR        scripts/slurm/stop.sh DIR
#
# Exit status: 0 started; 3 Slurm or munge is not installed, or not root (the test fails, saying so);
# 1 anything else (the daemons' logs are printed). scripts/slurm/install.sh installs the packages.
set -euo pipefail
export PATH="$PATH:/usr/sbin:/sbin"
here=$(cd "$(dirname "$0")" && pwd)

for tool in munged mungekey slurmctld slurmd sinfo sbatch squeue scontrol scancel; do
  if ! command -v "$tool" >/dev/null; then
    echo "slurm: $tool is not installed (scripts/slurm/install.sh installs Slurm)" >&2
    exit 3
  fi
done
if [[ $(id -u) != 0 ]]; then
  echo "slurm: a private cluster needs root (slurmd starts jobs through setuid)" >&2
  exit 3
fi

dir=${1:?usage: start.sh DIR}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
mkdir -p "$dir"/{etc,state,spool,log,run,munge,key}
# munged accepts a socket folder only if every folder on its path is o+x and not group- or
# world-writable.
chmod 755 "$dir" "$dir/munge"
chmod 700 "$dir/key"

give_up() {
  echo "slurm: $*" >&2
  tail -n 20 "$dir"/log/* >&2 2>/dev/null || true
  "$here/stop.sh" "$dir" >/dev/null 2>&1 || true
  exit 1
}

# Two free TCP ports, so that clusters of several tests can run side by side.
listening() { awk 'NR > 1 { print $2 }' /proc/net/tcp /proc/net/tcp6 2>/dev/null | grep -qi ":$(printf '%04X' "$1")\$"; }
free_port() {
  local port
  for _ in $(seq 100); do
    port=$((20000 + RANDOM % 30000))
    if ! listening "$port" && [[ $port != "${1:-}" ]]; then echo "$port"; return; fi
  done
  return 1
}
ctld_port=$(free_port) || give_up "no free port"
slurmd_port=$(free_port "$ctld_port") || give_up "no free port"
host=$(uname -n)
host=${host%%.*}
# Stable per DIR: Slurm keeps the cluster name in its state, and stop.sh finds this cluster's
# job processes by it.
cluster=seads$(printf %s "$dir" | cksum | cut -d' ' -f1)

socket="$dir/munge/socket"
[[ -s $dir/key/munge.key ]] || mungekey --create --keyfile="$dir/key/munge.key"
chmod 600 "$dir/key/munge.key"
munged --socket="$socket" --key-file="$dir/key/munge.key" --pid-file="$dir/run/munged.pid" \
  --log-file="$dir/log/munged.log" --seed-file="$dir/key/seed" </dev/null >>"$dir/log/munged.out" 2>&1 \
  || give_up "munged did not start"

cat >"$dir/etc/slurm.conf" <<CONF
ClusterName=$cluster
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
PlugStackConfig=$dir/etc/plugstack.conf
MailProg=/bin/true
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/log/jobcomp.txt
SchedulerType=sched/backfill
# Jobs start within about a second.
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
# A job that depends on a failed one is cancelled instead of pending forever.
DependencyParameters=kill_invalid_depend
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
MinJobAge=3600
KillWait=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=${SLURM_CPUS:-$(nproc)} State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
: >"$dir/etc/plugstack.conf"
# slurmd 22.05 always loads a cgroup plugin; only cgroup/v1 starts here without a cgroup fs.
printf 'CgroupPlugin=cgroup/v1\nIgnoreSystemd=yes\n' >"$dir/etc/cgroup.conf"
export SLURM_CONF="$dir/etc/slurm.conf"

slurmctld -f "$SLURM_CONF" </dev/null >>"$dir/log/slurmctld.out" 2>&1 || give_up "slurmctld did not start"
slurmd -f "$SLURM_CONF" -N "$host" </dev/null >>"$dir/log/slurmd.out" 2>&1 || give_up "slurmd did not start"

for _ in $(seq 100); do listening "$ctld_port" && break; sleep 0.05; done
deadline=$((SECONDS + 60))
until [[ $(sinfo -h -N -o %T 2>/dev/null | head -n1) == idle ]]; do
  ((SECONDS < deadline)) || give_up "the node is not idle after 60 s: $(sinfo -h -N -o '%T %E' 2>&1)"
  sleep 0.2
done
echo "export SLURM_CONF=$SLURM_CONF"
