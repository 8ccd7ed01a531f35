# SPDX-License-Identifier: BSD-2-Clause
"""pednav.read_imu and pednav.ImuLog: arrays in and out, bad arrays refused with a one-line ValueError."""
import numpy as np
import pytest

import pednav


@pytest.fixture(scope="module")
def log(forest):
    return forest["imu"]


def test_read_imu_arrays(forest, log):
    n = len(log)
    assert n == forest["summary"]["imu_samples"]
    assert log.t_s.shape == (n,) and log.t_s.dtype == np.float64
    assert log.gyro_radps.shape == (n, 3) and log.accel_mps2.shape == (n, 3)
    assert log.stance_label is None
    assert np.all(np.diff(log.t_s) > 0)
    assert log.gps_week == 2300
    assert log.report["rate_hz"] == pytest.approx(100.0, rel=1e-6)
    # The arrays are the file's numbers (imu.csv: gps_week, gps_tow_s, gyro x y z, accel x y z; SI, body frame).
    table = np.loadtxt(forest["files"]["imu"], delimiter=",", skiprows=1)
    np.testing.assert_array_equal(log.gyro_radps, table[:, 2:5])
    np.testing.assert_array_equal(log.accel_mps2, table[:, 5:8])
    np.testing.assert_allclose(log.t_s, table[:, 1], rtol=0, atol=1e-9)  # GPS time is held in integer ns


def test_read_imu_with_a_format_name(forest):
    cfg = forest["config"].to_dict()
    fmt = cfg["imu"]["format"]
    again = pednav.read_imu(forest["files"]["imu"], format=fmt)
    np.testing.assert_array_equal(again.t_s, forest["imu"].t_s)
    np.testing.assert_array_equal(again.gyro_radps, forest["imu"].gyro_radps)


def test_read_imu_errors(tmp_path, forest):
    with pytest.raises(FileNotFoundError):
        pednav.read_imu(tmp_path / "absent.csv", format="pyshoe")
    with pytest.raises(ValueError, match="format= is required"):
        pednav.read_imu(forest["files"]["imu"])
    with pytest.raises(ValueError, match="format"):
        pednav.read_imu(forest["files"]["imu"], format="no_such_preset")
    with pytest.raises(ValueError, match=r"imu\.format\."):
        pednav.read_imu(forest["files"]["imu"], format={"no_such_key": 3})


def test_imu_log_from_arrays_round_trip(log):
    again = pednav.ImuLog(log.t_s, log.gyro_radps, log.accel_mps2, gps_week=log.gps_week)
    np.testing.assert_array_equal(again.t_s, log.t_s)
    np.testing.assert_array_equal(again.gyro_radps, log.gyro_radps)
    np.testing.assert_array_equal(again.accel_mps2, log.accel_mps2)
    assert again.gps_week == log.gps_week


def test_float32_non_contiguous_and_lists_are_converted():
    t = np.arange(20, dtype=np.float64) * 0.01
    g = np.zeros((20, 6))
    g[:, ::2] = 0.001  # every other column: a non-contiguous (20, 3) view
    a = np.tile([0.0, 0.0, -9.81], (20, 1)).astype(np.float32)
    log = pednav.ImuLog(t, g[:, ::2], a)
    np.testing.assert_array_equal(log.gyro_radps, np.full((20, 3), 0.001))
    np.testing.assert_array_equal(log.accel_mps2, a.astype(np.float64))
    log2 = pednav.ImuLog(list(t), g[:, ::2].tolist(), a.tolist(), stance_label=np.ones(20, dtype=np.int32))
    assert log2.stance_label.dtype == np.uint8 and log2.stance_label.sum() == 20
    assert pednav.ImuLog(np.arange(20), g[:, ::2], a).t_s.dtype == np.float64  # int64 seconds


@pytest.mark.parametrize("t, gyro, accel, message", [
    (np.array([0.0, 0.01, np.nan]), np.zeros((3, 3)), np.zeros((3, 3)), r"t_s\[2\] is NaN"),
    (np.array([0.0, 0.01, 0.02]), np.array([[0, 0, 0], [0, np.inf, 0], [0, 0, 0]]), np.zeros((3, 3)),
     r"gyro_radps\[1, 1\] is infinite"),
    (np.array([0.0, 0.02, 0.01]), np.zeros((3, 3)), np.zeros((3, 3)), r"t_s\[2\]: time 0.010000 s is not after"),
    (np.array([0.0, 0.01, 0.01]), np.zeros((3, 3)), np.zeros((3, 3)), r"t_s\[2\].*not after"),
    (np.array([]), np.zeros((0, 3)), np.zeros((0, 3)), "empty"),
    (np.zeros(3), np.zeros((3, 2)), np.zeros((3, 3)), r"gyro_radps: shape \(3, 2\), expected \(N, 3\)"),
    (np.zeros(3), np.zeros((3, 3)), np.zeros(9), r"accel_mps2: shape \(9,\), expected \(N, 3\)"),
    (np.zeros((3, 1)), np.zeros((3, 3)), np.zeros((3, 3)), r"t_s: shape \(3, 1\), expected \(N,\)"),
    (np.arange(3) * 0.1, np.zeros((4, 3)), np.zeros((3, 3)), "one row per time stamp"),
    (np.array(["a", "b", "c"]), np.zeros((3, 3)), np.zeros((3, 3)), "t_s: dtype <U1 is not a real number type"),
    (np.arange(3) * 0.1, np.zeros((3, 3), dtype=complex), np.zeros((3, 3)), "gyro_radps: dtype complex128"),
    (np.arange(3) * 0.1, "gyro", np.zeros((3, 3)), "gyro_radps: dtype <U4"),
])
def test_bad_arrays_are_refused(t, gyro, accel, message):
    with pytest.raises(ValueError, match=message):
        pednav.ImuLog(t, gyro, accel)


def test_bad_stance_labels():
    t = np.arange(5) * 0.01
    with pytest.raises(ValueError, match=r"stance_label\[1\] is 2"):
        pednav.ImuLog(t, np.zeros((5, 3)), np.zeros((5, 3)), stance_label=[0, 2, 0, 0, 0])
    with pytest.raises(ValueError, match="4 labels for 5 samples"):
        pednav.ImuLog(t, np.zeros((5, 3)), np.zeros((5, 3)), stance_label=[0, 1, 0, 0])
    with pytest.raises(ValueError, match="gps_week"):
        pednav.ImuLog(t, np.zeros((5, 3)), np.zeros((5, 3)), gps_week=-1)
