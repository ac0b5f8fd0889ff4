#!/usr/bin/env bash
# Stops the cluster that scripts/slurm/start.sh started in DIR: cancels its jobs, stops its
# three daemons by the PIDs they recorded (never by name, so other clusters live on), and kills
# job processes of this cluster that outlived them. Idempotent; always exits 0.
#
#   scripts/slurm/stop.sh DIR [--rm]
set -uo pipefail
export PATH="$PATH:/usr/sbin:/sbin"
dir=${1:?usage: stop.sh DIR [--rm]}
export SLURM_CONF="$dir/etc/slurm.conf"

# The live process recorded in DIR/run/NAME.pid, if it is still NAME (not a reused PID).
recorded() {
  local pid
  pid=$(tr -dc 0-9 <"$dir/run/$1.pid" 2>/dev/null) || return 1
  [[ -n $pid && $(cat "/proc/$pid/comm" 2>/dev/null) == "$1" ]] || return 1
  echo "$pid"
}
# Zombies count as gone: exited daemons may wait a while to be reaped here.
alive() { [[ -r /proc/$1/stat && $(awk '{ print $3 }' "/proc/$1/stat" 2>/dev/null) != Z ]]; }
stop() {
  local pid
  pid=$(recorded "$1") || return 0
  kill -TERM "$pid" 2>/dev/null
  for _ in $(seq 200); do alive "$pid" || return 0; sleep 0.05; done
  kill -KILL "$pid" 2>/dev/null
  sleep 0.2
}

if recorded slurmctld >/dev/null && recorded slurmd >/dev/null; then
  jobs=$(squeue -h -o %A 2>/dev/null)
  [[ -n $jobs ]] && scancel $jobs 2>/dev/null
  for _ in $(seq 100); do
    [[ -z $(squeue -h -t running,completing,configuring -o %A 2>/dev/null) ]] && break
    sleep 0.1
  done
fi
stop slurmd
stop slurmctld
stop munged
# Job processes carry SLURM_CLUSTER_NAME; kill those of this cluster that escaped.
cluster=$(sed -n 's/^ClusterName=//p' "$SLURM_CONF" 2>/dev/null)
if [[ -n $cluster ]]; then
  for environ in /proc/[0-9]*/environ; do
    pid=${environ#/proc/}
    pid=${pid%/environ}
    [[ $pid == "$$" ]] && continue
    vars=$( { tr '\0' '\n' <"$environ"; } 2>/dev/null) || continue
    if grep -qx "SLURM_CLUSTER_NAME=$cluster" <<<"$vars" && grep -q '^SLURM_JOB_ID=' <<<"$vars"; then
      kill -KILL "$pid" 2>/dev/null
    fi
  done
fi
[[ ${2:-} == --rm ]] && rm -rf "$dir"
exit 0
