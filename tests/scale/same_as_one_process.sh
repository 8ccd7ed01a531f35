#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# Shared by the scale tests: runs the 12-run indoor_loops study as one process into WORK/one and checks that MERGED
# (a merged sharded study) has the same nees.csv, runs.csv without its wall_s column, and summary.json without its
# wall-clock and thread-count keys. Usage: same_as_one_process.sh PEDNAV ROOT WORK MERGED
set -euo pipefail
pednav="$1" root="$2" work="$3" merged="$4"
"$pednav" -q montecarlo "$root/datasets/indoor_loops.yaml" --runs 12 --jobs 2 --no-plots -o "$work/one"
cmp "$work/one/nees.csv" "$merged/nees.csv"
diff <(cut -d, -f1-3,5- "$work/one/runs.csv") <(cut -d, -f1-3,5- "$merged/runs.csv")
strip='import json,sys; d=json.load(open(sys.argv[1])); [d.pop(k) for k in ("wall_s","run_wall_s_sum","jobs","runs_done_now")]; print(json.dumps(d, sort_keys=True))'
diff <(python3 -c "$strip" "$work/one/summary.json") <(python3 -c "$strip" "$merged/summary.json")
