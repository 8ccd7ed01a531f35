#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# ctest scale.slurm_montecarlo (label slow): a single-node Slurm on localhost (Debian slurm-wlm + munge, installed by
# this script when missing; ../shared/notes/slurm_single_node.md) runs scripts/cluster/montecarlo_slurm.sbatch as an
# array of 4 shards, then the merge as a dependent job; the result must equal one `pednav montecarlo` process
# (wall-clock fields excluded). The daemons are started here and stopped on exit. Needs root (no sudo here).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
pednav="$(cd "$(dirname "${1:?usage: $0 PEDNAV_BINARY WORKDIR}")" && pwd)/$(basename "$1")"
work="${2:?usage: $0 PEDNAV_BINARY WORKDIR}"
t0=$(date +%s)
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi
rm -rf "$work"
mkdir -p "$work"/{state,spool,log,run}
work="$(cd "$work" && pwd)"
# munge: a key, its run folder, the daemon as user munge.
mkdir -p /etc/munge /run/munge /var/log/munge /var/lib/munge
[ -s /etc/munge/munge.key ] || head -c 1024 /dev/urandom > /etc/munge/munge.key
chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge
chmod 700 /etc/munge && chmod 400 /etc/munge/munge.key
pkill -x munged 2>/dev/null || true
runuser -u munge -- munged
host="$(hostname -s)"
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=pednavtest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=$(( $(free -m | awk '/^Mem:/{print $2}') - 512 )) State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
cleanup() {
  for p in slurmctld slurmd; do [ -s "$work/run/$p.pid" ] && kill "$(cat "$work/run/$p.pid")" 2>/dev/null || true; done
}
trap cleanup EXIT
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 30); do sinfo -h -o %T 2>/dev/null | grep -q idle && break; sleep 1; done
sinfo -h -o %T | grep -q idle || { echo "slurm: node not idle"; cat "$work/log/"*.log; exit 1; }
cd "$root"
out="$work/mc"
job=$(PEDNAV="$pednav" sbatch --parsable --array=1-4 --chdir="$root" --output="$work/log/task-%a.log" \
      --export=ALL,PEDNAV="$pednav" scripts/cluster/montecarlo_slurm.sbatch "$root/datasets/indoor_loops.yaml" 12 "$out")
merge=$(sbatch --parsable --dependency=afterok:"$job" --chdir="$root" --output="$work/log/merge.log" \
        --wrap "$pednav montecarlo-merge --no-plots $out/merged $out/shard_1 $out/shard_2 $out/shard_3 $out/shard_4")
for _ in $(seq 1 300); do
  [ -z "$(squeue -h -j "$job,$merge" 2>/dev/null)" ] && break
  sleep 1
done
[ -s "$out/merged/summary.json" ] || { echo "slurm: no merged summary"; cat "$work/log/"*.log; exit 1; }
"$root/tests/scale/same_as_one_process.sh" "$pednav" "$root" "$work" "$out/merged"
echo "slurm_montecarlo: 4 array tasks + dependent merge = one process ($(( $(date +%s) - t0 )) s including set-up)"
