#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""Benchmarks of the Python module (docs/performance.md "Python module").

1. pednav.run on datasets/forest_walk.yaml (mode tc) against `pednav run --mode tc` of the same configuration, alternating runs (the
   module: reading the inputs + the engine + the rows in memory; the CLI: the process, reading, the engine, writing).
2. Two forest walks (seeds 2 and 3) in two Python threads against one after the other (the GIL is released while the
   engine runs).

Usage: PYTHONPATH=build/python python3 bench/python_bench.py [--bin build/bin/pednav] [--repeats 5]
Prints the medians, the ratios and the process CPU time per wall second (> 1: the threads ran at once); nothing is
asserted. The machine's other load changes every figure: run it on an otherwise idle machine."""
import argparse
import atexit
import os
import pathlib
import shutil
import statistics
import subprocess
import tempfile
import threading
import time

import pednav

ROOT = pathlib.Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--bin", default=str(ROOT / "build" / "bin" / "pednav"))
parser.add_argument("--repeats", type=int, default=5)
args = parser.parse_args()

work = pathlib.Path(tempfile.mkdtemp(prefix="pednav_python_bench_"))
atexit.register(shutil.rmtree, work, True)
scenario = (ROOT / "datasets" / "forest_walk.yaml").read_text()
sims = []
for seed in (2, 3):
    path = work / f"forest_walk_seed{seed}.yaml"
    path.write_text(scenario.replace("seed: 2\n", f"seed: {seed}\n", 1))
    sims.append(pednav.simulate(path, out_dir=str(work / f"sim{seed}")))
config_path = sims[0]["files"]["config"]


cpu_s = {}


def timed(f, cpu_key=None):
    t0, c0 = time.perf_counter(), time.process_time()
    f()
    wall = time.perf_counter() - t0
    if cpu_key:
        cpu_s.setdefault(cpu_key, []).append((time.process_time() - c0) / wall)
    return wall


# 1. Module vs CLI, alternating.
module_s, cli_s = [], []
pednav.run(pednav.Config.from_yaml(config_path), mode="tc")  # warm the page cache and the module
for i in range(args.repeats):
    cli_s.append(timed(lambda: subprocess.run([args.bin, "run", config_path, "--mode", "tc", "-o",
                                               str(work / f"cli{i}")], check=True, capture_output=True)))
    module_s.append(timed(lambda: pednav.run(pednav.Config.from_yaml(config_path), mode="tc")))
m, c = statistics.median(module_s), statistics.median(cli_s)
print(f"forest_walk: pednav.run median {m:.3f} s, pednav run (CLI) median {c:.3f} s, "
      f"module / CLI = {m / c:.3f} ({100 * (m / c - 1):+.1f} %) over {args.repeats} alternating runs each")
print("  module runs:", " ".join(f"{x:.3f}" for x in module_s))
print("  CLI runs:   ", " ".join(f"{x:.3f}" for x in cli_s))

# 2. Two logs: serial vs two threads, alternating.
configs = [s["config"] for s in sims]


def serial():
    for cfg in configs:
        pednav.run(cfg, mode="tc")


def threaded():
    threads = [threading.Thread(target=pednav.run, args=(cfg,), kwargs={"mode": "tc"}) for cfg in configs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


serial_s, threaded_s = [], []
for _ in range(args.repeats):
    serial_s.append(timed(serial, "serial"))
    threaded_s.append(timed(threaded, "threads"))
s, t = statistics.median(serial_s), statistics.median(threaded_s)
print(f"two forest walks: serial median {s:.3f} s, two threads median {t:.3f} s, threads / serial = {t / s:.3f} "
      f"on {os.cpu_count()} cores")
print("  serial:  ", " ".join(f"{x:.3f}" for x in serial_s))
print("  threads: ", " ".join(f"{x:.3f}" for x in threaded_s))
print(f"  process CPU time / wall time (cores in use): serial median {statistics.median(cpu_s['serial']):.2f}, "
      f"threads median {statistics.median(cpu_s['threads']):.2f}")
print(f"  load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
