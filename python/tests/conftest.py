# SPDX-License-Identifier: BSD-2-Clause
"""Shared fixtures of the pednav module's tests (ctest label python; docs/python.md).

The simulated data sets are made once per session with pednav.simulate; the CLI outputs they are compared with come
from the pednav executable of the same build (PEDNAV_BIN, set by ctest)."""
import os
import pathlib
import subprocess

import pytest

import pednav

SOURCE_DIR = pathlib.Path(os.environ.get("PEDNAV_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
PEDNAV_BIN = os.environ.get("PEDNAV_BIN", str(SOURCE_DIR / "build" / "bin" / "pednav"))


def cli(*args, check=True):
    """Run the pednav executable; returns the CompletedProcess (stdout and stderr as text)."""
    return subprocess.run([PEDNAV_BIN, *map(str, args)], capture_output=True, text=True, check=check)


@pytest.fixture(scope="session")
def forest(tmp_path_factory):
    """datasets/forest_walk.yaml simulated once (18 min, tc with base): pednav.simulate's dict."""
    return pednav.simulate(SOURCE_DIR / "datasets" / "forest_walk.yaml",
                           out_dir=str(tmp_path_factory.mktemp("forest_sim")))


@pytest.fixture(scope="session")
def square(tmp_path_factory):
    """datasets/square_75m.yaml simulated once (about 1 min): the second log of the thread tests."""
    return pednav.simulate(SOURCE_DIR / "datasets" / "square_75m.yaml",
                           out_dir=str(tmp_path_factory.mktemp("square_sim")))


@pytest.fixture(scope="session")
def forest_result(forest):
    """pednav.run on the forest walk's config.yaml in mode tc."""
    return pednav.run(forest["config"], mode="tc")


@pytest.fixture(scope="session")
def forest_cli(forest, tmp_path_factory):
    """`pednav run --mode tc` of the same configuration: its output folder."""
    out = tmp_path_factory.mktemp("forest_cli")
    cli("run", forest["files"]["config"], "--mode", "tc", "-o", out)
    return out
