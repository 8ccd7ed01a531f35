#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# A pednav Monte Carlo study sharded over GNU parallel (local cores, or other machines with --sshloginfile), then
# merged: the result is what one `pednav montecarlo` process writes (docs/scale.md).
# Usage: scripts/cluster/montecarlo_parallel.sh SCENARIO.yaml RUNS SHARDS OUT [extra pednav montecarlo flags...]
#   Env: PEDNAV (default build/bin/pednav), PARALLEL_OPTS (e.g. "--sshloginfile hosts.txt --workdir ."; every host
#   needs the same pednav build and the scenario at the same path), JOBS_PER_SHARD (threads per shard, default 1).
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 SCENARIO.yaml RUNS SHARDS OUT [montecarlo flags...]" >&2; exit 2; }
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
pednav="${PEDNAV:-$root/build/bin/pednav}"
scenario="$1" runs="$2" shards="$3" out="$4"
shift 4
mkdir -p "$out"
# One shard per job; a failed shard fails the study (--halt now,fail=1). Re-running resumes: done runs are kept.
# shellcheck disable=SC2086
parallel --will-cite --halt now,fail=1 ${PARALLEL_OPTS:-} \
  "$pednav" -q montecarlo "$scenario" --runs "$runs" --jobs "${JOBS_PER_SHARD:-1}" --no-plots --shard {}/"$shards" \
  -o "$out/shard_{}" "$@" ::: $(seq 1 "$shards")
dirs=()
for k in $(seq 1 "$shards"); do dirs+=("$out/shard_$k"); done
"$pednav" montecarlo-merge "$out/merged" "${dirs[@]}"
