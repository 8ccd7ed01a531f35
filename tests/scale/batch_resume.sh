#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# ctest scale.batch_resume (label scale): `pednav batch` over the shared foot logs and a simulated scenario (run and
# gnss), once uninterrupted and once killed (SIGKILL) halfway and restarted: the restart finishes only what was left
# and index.csv / summary.csv are the same as the uninterrupted run's (docs/scale.md).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
pednav="${1:?usage: $0 PEDNAV_BINARY WORKDIR}"
work="${2:?usage: $0 PEDNAV_BINARY WORKDIR}"
rm -rf "$work"
mkdir -p "$work"
"$pednav" -q simulate "$root/datasets/forest_walk.yaml" -o "$work/forest"
{
  echo "items:"
  for f in "$root"/datasets/foot/*.yaml; do
    echo "  - {name: $(basename "$f" .yaml), command: run, config: $f}"
  done
  echo "  - {name: forest_walk_tc, command: run, config: forest/config.yaml, mode: tc}"
  echo "  - {name: forest_walk_gnss, command: gnss, config: forest/config.yaml}"
  echo "  - {name: broken, command: run, config: forest/config.yaml, mode: ins}"  # mode ins without yaw: a failure
} > "$work/manifest.yaml"
n_items=$(grep -c '  - {' "$work/manifest.yaml")
set +e
"$pednav" -q batch "$work/manifest.yaml" -o "$work/a"
rc_a=$?
set -e
[ "$rc_a" = 1 ] || { echo "batch: expected exit 1 (one failing item), got $rc_a"; exit 1; }
grep -q '^broken,run,.*,failed,' "$work/a/index.csv" || { echo "batch: the failing item is not in index.csv"; exit 1; }
# Interrupted: kill the batch once 4 items have finished, then run it again.
"$pednav" -q batch "$work/manifest.yaml" -o "$work/b" > "$work/b.log" 2>&1 &
pid=$!
for _ in $(seq 1 600); do
  [ "$(ls "$work"/b/*/batch_status.json 2>/dev/null | wc -l)" -ge 4 ] && break
  sleep 0.05
done
kill -9 "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
done_before=$(ls "$work"/b/*/batch_status.json 2>/dev/null | wc -l)
[ "$done_before" -lt "$n_items" ] || { echo "batch: finished before it could be killed ($done_before items)"; exit 1; }
set +e
"$pednav" batch "$work/manifest.yaml" -o "$work/b" > "$work/b2.log" 2>&1
set -e
grep -q "($done_before done before)" "$work/b2.log" || { echo "batch: restart did not skip the $done_before done items"; cat "$work/b2.log"; exit 1; }
sed "s#$work/a#X#g" "$work/a/index.csv" > "$work/ia" && sed "s#$work/b#X#g" "$work/b/index.csv" > "$work/ib"
diff "$work/ia" "$work/ib"
diff "$work/a/summary.csv" "$work/b/summary.csv"
echo "batch_resume: $n_items items; killed after $done_before, restarted: same index and summary"
