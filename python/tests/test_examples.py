# SPDX-License-Identifier: BSD-2-Clause
"""The example scripts run headless (no display: matplotlib's Agg backend) and write their figures."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

PYSHOE_LOG = SOURCE_DIR.parent / "shared" / "datasets" / "foot_pyshoe_vicon" / "csv" / "2017-11-22-11-22-03.csv"


def run_example(name, out):
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    cp = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / name), "-o", str(out)], env=env,
                        capture_output=True, text=True)
    assert cp.returncode == 0, cp.stderr
    return cp.stdout


def test_forest_walk_example(tmp_path):
    stdout = run_example("forest_walk.py", tmp_path)
    assert "smoothed: horizontal RMS" in stdout
    for name in ["track.png", "track.svg", "error.png", "error.svg"]:
        assert (tmp_path / name).stat().st_size > 1000, name


def test_pyshoe_example(tmp_path):
    if not PYSHOE_LOG.exists():
        if os.environ.get("CI") == "true":
            pytest.fail(f"{PYSHOE_LOG} missing (CI=true: the shared data sets are required)")
        pytest.skip(f"{PYSHOE_LOG} missing (../shared/datasets/foot_pyshoe_vicon)")
    stdout = run_example("pyshoe_trial.py", tmp_path)
    assert "horizontal RMS" in stdout
    for name in ["error.png", "error.svg"]:
        assert (tmp_path / name).stat().st_size > 1000, name
