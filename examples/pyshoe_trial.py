#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""A PyShoe Vicon trial from Python: read_imu + run + compare against the Vicon truth, plot the track.

Usage: PYTHONPATH=build/python python3 examples/pyshoe_trial.py [-o OUTDIR] [--trial 2017-11-22-11-22-03]
Needs ../shared/datasets/foot_pyshoe_vicon (see datasets/README.md). Without it the script says so and exits 0,
except under CI=true where missing data is a failure (exit 1), as for the data tests."""
import argparse
import csv
import os
import pathlib
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import pednav  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("-o", "--out", default=os.path.join(tempfile.gettempdir(), "pednav_examples", "pyshoe_trial"))
parser.add_argument("--trial", default="2017-11-22-11-22-03")
parser.add_argument("--shared", default=str(ROOT.parent / "shared" / "datasets"))
args = parser.parse_args()

log_csv = pathlib.Path(args.shared) / "foot_pyshoe_vicon" / "csv" / f"{args.trial}.csv"
if not log_csv.exists():
    print(f"pyshoe_trial: {log_csv} not found (../shared/datasets/foot_pyshoe_vicon)", file=sys.stderr)
    sys.exit(1 if os.environ.get("CI") == "true" else 0)
out = pathlib.Path(args.out)
out.mkdir(parents=True, exist_ok=True)

# %% 1. The log through the `pyshoe` format preset (LORD 3DM-GX5-25, 200 Hz, relative time -> GPS week 0).
imu = pednav.read_imu(log_csv, format="pyshoe")
print(f"{log_csv.name}: {len(imu)} samples at {imu.report['rate_hz']:.1f} Hz, {imu.report['duration_s']:.1f} s")

# %% 2. The Vicon truth as a local-frame reference (scripts/foot_reference: e = gt_y, n = gt_x, u = gt_z).
reference = out / f"vicon_{args.trial}.csv"
with open(log_csv, newline="") as f, open(reference, "w", newline="") as g:
    w = csv.writer(g)
    w.writerow(["gps_week", "gps_tow_s", "e_m", "n_m", "u_m"])
    for row in csv.DictReader(f):
        w.writerow([0, row["t_s"], row["gt_y_m"], row["gt_x_m"], row["gt_z_m"]])

# %% 3. INS/ZUPT with the repository's configuration of this sensor, on the log read above.
config = pednav.Config.from_yaml(ROOT / "datasets" / "foot" / "pyshoe_vicon_2017-11-22-11-22-03.yaml")
result = pednav.run(config, imu=imu)
print(f"{result.summary['zupt']['updates']} ZUPTs, {len(result.forward['gps_tow_s'])} output epochs")

# %% 4. Errors against Vicon, aligned at the start (pednav compare --align start).
ev = pednav.compare(result, reference, align="start")
e = ev["evaluation"]
print(f"horizontal RMS {e['horizontal_rms_m']:.3f} m, max {e['horizontal_max_m']:.3f} m over "
      f"{e['epochs_compared']} epochs")

# %% 5. Error against time.
fig, ax = plt.subplots(figsize=(8, 4))
err = ev["errors"]
ax.plot(err["gps_tow_s"], err["horizontal_m"], lw=1, label="horizontal error")
ax.set_xlabel("log time [s]")
ax.set_ylabel("[m]")
ax.set_title(f"PyShoe trial {args.trial}: INS/ZUPT vs Vicon")
ax.legend()
for ext in ("png", "svg"):
    fig.savefig(out / f"error.{ext}", dpi=120)
plt.close(fig)
print("figures in", out)
