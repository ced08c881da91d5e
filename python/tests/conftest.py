# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared helpers for the tests: a synthetic results folder and running the plot command."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

PYTHON_DIR = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(PYTHON_DIR))

SERIES_CSV = """time,step,F_moved,broken,energy
0,0,0,0,1
0.5,10,2,nan,-1
1,20,inf,5,0
1.5,30,4,-inf,2
2,40,5,10,4
"""


@pytest.fixture
def results(tmp_path):
    """A results folder holding SERIES_CSV; call it with the plots to also write plots.json."""
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "series.csv").write_text(SERIES_CSV)

    def with_plots(*plots):
        (folder / "plots.json").write_text(json.dumps({"plots": list(plots)}))
        return folder

    with_plots.path = folder
    return with_plots


def run_plot(*args, python_code=None, extra_path=()):
    """Runs `python3 -m arlequin.plot ARGS` (or `python3 -c python_code ARGS`) in a subprocess."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*map(str, extra_path), str(PYTHON_DIR)]))
    command = [sys.executable, "-c", python_code] if python_code else [sys.executable, "-m", "arlequin.plot"]
    return subprocess.run([*command, *map(str, args)], capture_output=True, text=True, env=env, timeout=60)
