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
"$pednav" -q montecarlo "$root/datasets/indoor_loops.yaml" --runs 12 --jobs 2 --no-plots -o "$work/one"
cmp "$work/one/nees.csv" "$work/par/merged/nees.csv"
diff <(cut -d, -f1-3,5- "$work/one/runs.csv") <(cut -d, -f1-3,5- "$work/par/merged/runs.csv")
strip='import json,sys; d=json.load(open(sys.argv[1])); [d.pop(k) for k in ("wall_s","run_wall_s_sum","jobs","runs_done_now")]; print(json.dumps(d, sort_keys=True))'
diff <(python3 -c "$strip" "$work/one/summary.json") <(python3 -c "$strip" "$work/par/merged/summary.json")
echo "parallel_montecarlo: 4 shards under GNU parallel merged = one process"
