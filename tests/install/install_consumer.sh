#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# ctest install.find_package_consumer (label scenario): `cmake --install` of the build into a prefix, then a tiny
# project outside the tree (tests/install/consumer) configured with find_package(pednav) against that prefix, built,
# and run on datasets/indoor_loops.yaml in memory (simulate + INS/ZUPT engine): it must close within 1 %.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:?usage: $0 BUILD_DIR WORKDIR}"
work="${2:?usage: $0 BUILD_DIR WORKDIR}"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -f "$work/prefix/lib/cmake/pednav/pednavConfig.cmake"
test -f "$work/prefix/include/pednav/fusion/engine.hpp"
cmake -S "$root/tests/install/consumer" -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer" "$root/datasets/indoor_loops.yaml"
