#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""The seed 004 forest walk from Python, in the style of a notebook: simulate, run, compare, plot.

Usage: PYTHONPATH=build/python python3 examples/forest_walk.py [-o OUTDIR]
Writes OUTDIR/track.png, track.svg, error.png, error.svg (default OUTDIR: $TMPDIR/pednav_examples/forest_walk) and
prints the evaluation of the forward and smoothed solutions against the simulator's truth. No display needed
(matplotlib's Agg backend)."""
import argparse
import os
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pednav  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("-o", "--out", default=os.path.join(tempfile.gettempdir(), "pednav_examples", "forest_walk"))
args = parser.parse_args()
out = pathlib.Path(args.out)
out.mkdir(parents=True, exist_ok=True)

# %% 1. Simulate the walk: truth, foot IMU, rover + base RINEX and a config.yaml ready for a run.
sim = pednav.simulate(ROOT / "datasets" / "forest_walk.yaml", out_dir=str(out / "data"))
print(f"simulated {sim['summary']['distance_m']:.0f} m in {sim['summary']['duration_s']:.0f} s "
      f"({len(sim['imu'])} IMU samples)")

# %% 2. Run the tightly coupled filter and the RTS smoother (a tqdm bar when tqdm is installed). The simulator's
# config.yaml says mode gnss (for `pednav gnss`); mode="tc" is `pednav run --mode tc`.
result = pednav.run(sim["config"], mode="tc", progress=True)
print("initialization:", result.summary["initialization"])

# %% 3. Compare both solutions with the truth.
fwd = pednav.compare(result, sim["files"]["truth"])
smo = pednav.compare(result, sim["files"]["truth"], which="smoothed")
for name, ev in [("forward", fwd), ("smoothed", smo)]:
    e = ev["evaluation"]
    print(f"{name:8s}: horizontal RMS {e['horizontal_rms_m']:.2f} m, p95 {e['horizontal_p95_m']:.2f} m, "
          f"max {e['horizontal_max_m']:.2f} m over {e['epochs_compared']} epochs")


# %% 4. The track in east/north metres about the start (truth, forward, smoothed).
def east_north(columns, lat0, lon0):
    r = 6378137.0
    e = np.radians(columns["lon_deg"] - lon0) * r * np.cos(np.radians(lat0))
    n = np.radians(columns["lat_deg"] - lat0) * r
    return e, n


truth = sim["truth"]
lat0, lon0 = truth["lat_deg"][0], truth["lon_deg"][0]
fig, ax = plt.subplots(figsize=(7, 6))
for label, cols, style in [("truth", truth, "k-"), ("forward", result.forward, "C1-"),
                           ("smoothed", result.smoothed, "C0-")]:
    e, n = east_north(cols, lat0, lon0)
    ax.plot(e, n, style, lw=1, label=label)
ax.set_aspect("equal")
ax.set_xlabel("east [m]")
ax.set_ylabel("north [m]")
ax.set_title("forest walk: track")
ax.legend()
for ext in ("png", "svg"):
    fig.savefig(out / f"track.{ext}", dpi=120)
plt.close(fig)

# %% 5. Horizontal error against time with the filter's own 3σ.
fig, ax = plt.subplots(figsize=(8, 4))
for label, ev, color in [("forward", fwd, "C1"), ("smoothed", smo, "C0")]:
    err = ev["errors"]
    t = err["gps_tow_s"] - err["gps_tow_s"][0]
    sigma_h = np.hypot(err["sd_e_m"], err["sd_n_m"])
    ax.plot(t, err["horizontal_m"], color=color, lw=1, label=f"{label} error")
    ax.plot(t, 3 * sigma_h, color=color, lw=1, ls="--", label=f"{label} 3σ")
ax.set_xlabel("time since start [s]")
ax.set_ylabel("horizontal [m]")
ax.set_title("forest walk: horizontal error and 3σ")
ax.legend()
for ext in ("png", "svg"):
    fig.savefig(out / f"error.{ext}", dpi=120)
plt.close(fig)
print("figures in", out)
