# SPDX-License-Identifier: BSD-2-Clause
"""pednav.run: the forward and smoothed solutions of `pednav run` to the last digit written, in memory."""
import csv
import json
import os
import queue
import signal
import threading
import time

import numpy as np
import pytest

import pednav
from conftest import cli

# The writer's format per solution.csv column (io/solution_writer.cpp): digits after the point, or None: integer.
DIGITS = {"gps_week": None, "gps_tow_s": 3, "lat_deg": 9, "lon_deg": 9, "h_m": 4, "x_m": 4, "y_m": 4, "z_m": 4,
          "vn_mps": 4, "ve_mps": 4, "vd_mps": 4, "roll_deg": 4, "pitch_deg": 4, "yaw_deg": 4, "sd_n_m": 4,
          "sd_e_m": 4, "sd_d_m": 4, "sd_yaw_deg": 4, "n_sats_used": None, "n_sats_rejected": None, "zupt": None,
          "hdop": 2, "pdop": 2}


def formatted(columns, name, k):
    v = columns[name][k]
    if DIGITS[name] is None:
        return str(int(v))
    if np.isnan(v):
        return ""
    return f"{v:.{DIGITS[name]}f}"


def assert_columns_equal_csv(columns, path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(columns["gps_tow_s"]) > 0
    for name in DIGITS:
        got = [formatted(columns, name, k) for k in range(len(rows))]
        want = [r[name] for r in rows]
        assert got == want, f"column {name} differs from {path}"


def test_forward_and_smoothed_equal_the_cli_digits(forest_result, forest_cli):
    assert_columns_equal_csv(forest_result.forward, forest_cli / "solution.csv")
    assert forest_result.smoothed is not None
    assert_columns_equal_csv(forest_result.smoothed, forest_cli / "smoothed.csv")


def test_written_files_equal_the_cli_files(forest_result, forest_cli, tmp_path):
    forest_result.write(str(tmp_path))
    for name in ["solution.csv", "smoothed.csv", "solution.pos", "solution_smoothed.pos", "residuals.csv",
                 "config.resolved.yaml"]:
        assert (tmp_path / name).read_bytes() == (forest_cli / name).read_bytes(), name
    a = json.loads((tmp_path / "summary.json").read_text())
    b = json.loads((forest_cli / "summary.json").read_text())
    a.pop("wall_s"), b.pop("wall_s")
    assert a == b
    for name in ["evaluation.json", "evaluation_smoothed.json"]:
        a = json.loads((tmp_path / name).read_text())
        b = json.loads((forest_cli / name).read_text())
        # The solution's file name: "solution.csv" in memory, the CLI's output path there.
        assert a["solution"].pop("file") in b["solution"].pop("file")
        assert a == b, name


def test_summary_and_residuals(forest_result, forest_cli):
    s = forest_result.summary
    cli_summary = json.loads((forest_cli / "summary.json").read_text())
    assert list(s) == list(cli_summary)  # same keys in the same order
    assert s["output_epochs"] == len(forest_result.forward["gps_tow_s"])
    r = forest_result.residuals
    with open(forest_cli / "residuals.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(r["sat"]) == len(rows)
    assert [f"{v:.4f}" for v in r["innovation"][:200]] == [row["innovation"] for row in rows[:200]]
    assert list(r["sat"][:200]) == [row["sat"] for row in rows[:200]]
    assert int(r["rejected"].sum()) == sum(int(row["rejected"]) for row in rows)
    # The simulator's config has the truth as reference: evaluation.json in memory.
    cli_eval = json.loads((forest_cli / "evaluation.json").read_text())
    assert forest_result.evaluation["horizontal_rms_m"] == cli_eval["horizontal_rms_m"]
    assert s["evaluation"] == cli_summary["evaluation"]


def test_run_from_arrays_equals_run_from_the_file(square):
    log = square["imu"]
    arrays = pednav.ImuLog(log.t_s, log.gyro_radps, log.accel_mps2, gps_week=log.gps_week)
    a = pednav.run(square["config"], mode="tc")
    b = pednav.run(square["config"], imu=arrays, mode="tc")
    for k in a.forward:
        np.testing.assert_array_equal(a.forward[k], b.forward[k], err_msg=k)


def test_mode_errors_are_the_cli_messages(square):
    with pytest.raises(ValueError, match="mode: gps"):
        pednav.run(square["config"], mode="gps")
    # A mode gnss configuration runs the tc filter when it has an IMU log; without one, the CLI's message.
    d = square["config"].to_dict()
    d["mode"] = "gnss"
    d.pop("imu", None)
    with pytest.raises(ValueError, match="needs imu.file"):
        pednav.run(pednav.Config.from_dict(d))
    # ins without an initial position: the engine's message, as `pednav run --mode ins` prints it.
    with pytest.raises(RuntimeError) as e:
        pednav.run(square["config"], mode="ins")
    cp = cli("run", square["files"]["config"], "--mode", "ins", "-o", square["out_dir"] + "/ins", check=False)
    assert cp.returncode != 0 and str(e.value) in cp.stderr


def test_engine_failure_is_runtime_error(square):
    log = square["imu"]
    few = pednav.ImuLog(log.t_s[:5], log.gyro_radps[:5], log.accel_mps2[:5], gps_week=log.gps_week)
    with pytest.raises(RuntimeError, match="fewer than 10 samples"):
        pednav.run(square["config"], imu=few, mode="tc")


def test_progress_callback(square):
    seen = []
    pednav.run(square["config"], mode="tc", progress=seen.append)
    assert seen and seen[-1] == 1.0
    assert all(0.0 <= f <= 1.0 for f in seen)
    assert seen == sorted(seen)


def test_progress_exception_stops_the_run(square):
    class Stop(Exception):
        pass

    def progress(f):
        raise Stop()

    with pytest.raises(Stop):
        pednav.run(square["config"], mode="tc", progress=progress)


def test_progress_true_uses_tqdm_when_importable(square, monkeypatch):
    import sys
    import types
    updates = []

    class FakeBar:
        def __init__(self, total, desc, unit):
            self.total = total

        def update(self, n):
            updates.append(n)

        def close(self):
            updates.append("closed")

    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    pednav.run(square["config"], mode="tc", progress=True)
    assert updates[-1] == "closed"
    assert sum(u for u in updates if u != "closed") == 100


def test_ctrl_c_raises_keyboard_interrupt_and_stops(forest, forest_result):
    # The first progress call (a C function: no Python signal handling runs inside it) wakes a thread that sends
    # SIGINT; the engine hook's PyErr_CheckSignals sees it at its next call and the run ends with KeyboardInterrupt.
    wake = queue.SimpleQueue()

    def interrupt():
        wake.get()
        os.kill(os.getpid(), signal.SIGINT)

    killer = threading.Thread(target=interrupt)
    killer.start()
    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        pednav.run(forest["config"], mode="tc", progress=wake.put)
    stopped_s = time.monotonic() - t0
    killer.join()
    # The engine state is per run: the next run gives the same solution as before.
    again = pednav.run(forest["config"], mode="tc")
    np.testing.assert_array_equal(again.forward["x_m"], forest_result.forward["x_m"])
    print(f"stopped after {stopped_s:.2f} s")


def test_to_pandas(forest_result):
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pandas"):
            forest_result.to_pandas()
        return
    df = forest_result.to_pandas("smoothed")
    assert list(df.columns)[:3] == ["gps_week", "gps_tow_s", "lat_deg"]
