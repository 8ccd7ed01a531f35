# SPDX-License-Identifier: BSD-2-Clause
"""pednav.Config: the validation and the one-line messages of `pednav config-check`."""
import pytest

import pednav
from conftest import SOURCE_DIR, cli

PYSHOE_CONFIG = SOURCE_DIR / "datasets" / "foot" / "pyshoe_auto.yaml"


def test_from_yaml_reads_the_simulated_config(forest):
    c = pednav.Config.from_yaml(forest["files"]["config"])
    assert c.mode == "tc"  # the simulator's config.yaml (the main job's mode)
    assert c.source_file == forest["files"]["config"]
    # The resolved YAML is what `pednav config-check` prints.
    assert c.to_yaml() == cli("config-check", forest["files"]["config"]).stdout


def test_to_dict_round_trip(forest):
    c = pednav.Config.from_yaml(forest["files"]["config"])
    d = c.to_dict()
    assert d["mode"] == "tc"
    assert isinstance(d["mechanization_rate_hz"], float) or isinstance(d["mechanization_rate_hz"], int)
    again = pednav.Config.from_dict(d)
    assert again.to_yaml() == c.to_yaml()


def test_from_dict_unknown_key_names_its_yaml_path(forest):
    d = pednav.Config.from_yaml(forest["files"]["config"]).to_dict()
    d["zupt"]["no_such_key"] = 1
    with pytest.raises(ValueError) as e:
        pednav.Config.from_dict(d)
    # The key path, without line numbers (they would be those of the YAML made from the dict).
    assert str(e.value) == "config: zupt.no_such_key: unknown key"


def test_value_error_is_the_config_check_message(forest):
    # Next to the simulated config, so that its relative file names resolve.
    bad = f"{forest['out_dir']}/bad_config.yaml"
    with open(forest["files"]["config"]) as f, open(bad, "w") as g:
        g.write(f.read() + "fault_rejection:\n  probability: 1.5\n")
    cp = cli("config-check", bad, check=False)
    assert cp.returncode != 0
    cli_lines = [line for line in cp.stderr.splitlines() if "fault_rejection.probability" in line]
    assert len(cli_lines) == 1, cp.stderr
    with pytest.raises(ValueError) as e:
        pednav.Config.from_yaml(bad)
    assert str(e.value) == cli_lines[0].split("error: ", 1)[1]


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        pednav.Config.from_yaml(tmp_path / "absent.yaml")


def test_missing_input_file_raises_file_not_found(tmp_path):
    y = tmp_path / "c.yaml"
    y.write_text(PYSHOE_CONFIG.read_text().replace("../../../shared/datasets/foot_pyshoe_vicon/csv/", str(tmp_path) + "/"))
    with pytest.raises(FileNotFoundError, match="imu.file"):
        pednav.Config.from_yaml(y)


def test_from_dict_type_error_is_value_error():
    with pytest.raises(ValueError, match="mechanization_rate_hz"):
        pednav.Config.from_dict({"mode": "ins", "mechanization_rate_hz": "fast"})
    with pytest.raises(ValueError, match="cannot be written as YAML"):
        pednav.Config.from_dict({"mode": object()})
