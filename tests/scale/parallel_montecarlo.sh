#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# ctest scale.parallel_montecarlo (label scale): scripts/cluster/montecarlo_parallel.sh runs 4 shards of 12 runs under
# GNU parallel and merges them; the result must equal one `pednav montecarlo` process (wall-clock fields excluded).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
pednav="${1:?usage: $0 PEDNAV_BINARY WORKDIR}"
work="${2:?usage: $0 PEDNAV_BINARY WORKDIR}"
command -v parallel >/dev/null || { echo "GNU parallel not installed (scripts/setup installs it)"; exit 1; }
rm -rf "$work"
mkdir -p "$work"
PEDNAV="$pednav" "$root/scripts/cluster/montecarlo_parallel.sh" "$root/datasets/indoor_loops.yaml" 12 4 "$work/par" --no-plots
"$root/tests/scale/same_as_one_process.sh" "$pednav" "$root" "$work" "$work/par/merged"
echo "parallel_montecarlo: 4 shards under GNU parallel merged = one process"
