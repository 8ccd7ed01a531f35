# SPDX-License-Identifier: BSD-2-Clause
"""pednav.gnss, simulate, compare, calibrate, detect_stance against the CLI commands of the same names."""
import csv
import json

import numpy as np
import pytest

import pednav
from conftest import cli


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_simulate_outputs(forest):
    assert set(forest) >= {"out_dir", "truth", "imu", "config", "files", "summary"}
    for key in ["truth", "imu", "rover_obs", "base_obs", "nav", "config"]:
        assert key in forest["files"]
    truth = forest["truth"]
    assert list(truth)[:14] == ["gps_week", "gps_tow_s", "lat_deg", "lon_deg", "h_m", "x_m", "y_m", "z_m", "vn_mps",
                                "ve_mps", "vd_mps", "roll_deg", "pitch_deg", "yaw_deg"]
    assert len(truth["gps_tow_s"]) == forest["summary"]["truth_rows"]
    assert forest["summary"]["distance_m"] == pytest.approx(900, rel=0.1)  # the scenario's ~900 m walk


def test_simulate_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        pednav.simulate(tmp_path / "absent.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nno_such_key: 1\n")
    with pytest.raises(ValueError, match="no_such_key"):
        pednav.simulate(bad)


def test_gnss_equals_cli(forest, tmp_path):
    g = pednav.gnss(forest["config"])
    assert g["out_dir"] is None  # a temporary folder, removed
    cli("gnss", forest["files"]["config"], "-o", tmp_path)
    rows = read_csv(tmp_path / "gnss.csv")
    assert len(rows) == len(g["solution"]["gps_tow_s"]) > 0
    for name in ["gps_tow_s", "x_m", "y_m", "z_m"]:
        np.testing.assert_array_equal(g["solution"][name], [float(r[name]) for r in rows])
    cli_summary = json.loads((tmp_path / "summary.json").read_text())
    assert g["summary"]["epochs_solved"] == cli_summary["epochs_solved"]


def test_compare_paths_equal_cli(forest, forest_cli, tmp_path):
    sol, ref = forest_cli / "solution.csv", forest["files"]["truth"]
    ev = pednav.compare(str(sol), ref)
    cli("compare", sol, ref, "-o", tmp_path, "--no-plot")
    assert ev["evaluation"] == json.loads((tmp_path / "evaluation.json").read_text())
    rows = read_csv(tmp_path / "errors.csv")
    assert [f"{v:.4f}" for v in ev["errors"]["horizontal_m"]] == [r["horizontal_m"] for r in rows]
    assert ev["markdown"] == (tmp_path / "evaluation.md").read_text()


def test_compare_result_in_memory(forest, forest_result, forest_cli):
    mem = pednav.compare(forest_result, forest["files"]["truth"])["evaluation"]
    disk = pednav.compare(str(forest_cli / "solution.csv"), forest["files"]["truth"])["evaluation"]
    assert mem["epochs_compared"] == disk["epochs_compared"]
    # The file holds positions to 0.1 mm: the statistics agree to that.
    assert mem["horizontal_rms_m"] == pytest.approx(disk["horizontal_rms_m"], abs=2e-4)


def test_compare_errors(forest, tmp_path):
    with pytest.raises(FileNotFoundError):
        pednav.compare(tmp_path / "absent.csv", forest["files"]["truth"])
    with pytest.raises(ValueError, match="align: sideways"):
        pednav.compare(forest["files"]["truth"], forest["files"]["truth"], align="sideways")


def test_calibrate_equals_cli(forest, tmp_path):
    c = pednav.calibrate(forest["imu"], config=forest["config"])
    cli("calibrate", forest["files"]["config"], "-o", tmp_path)
    assert c["calibration"] == json.loads((tmp_path / "calibration.json").read_text())
    assert c["yaml"] == (tmp_path / "calibration.yaml").read_text()


def test_detect_stance_equals_cli(forest, tmp_path):
    d = pednav.detect_stance(forest["imu"], config=forest["config"])
    cli("zupt", forest["files"]["config"], "-o", tmp_path)
    rows = read_csv(tmp_path / "zupt.csv")
    assert len(rows) == len(d["stance"])
    np.testing.assert_array_equal(d["stance"], [r["stance"] == "1" for r in rows])
    assert d["detector"] == forest["config"].to_dict()["zupt"]["detector"]
    for detector in ["mv", "shoe", "hmm"]:
        other = pednav.detect_stance(forest["imu"], detector=detector)
        assert other["detector"] == detector
        # Stance share of the simulated gait (30 % of each stride, plus the rests): well inside (0.2, 0.7).
        assert 0.2 < other["stance"].mean() < 0.7, detector
    with pytest.raises(ValueError):
        pednav.detect_stance(forest["imu"], detector="no_such_detector")
