# SPDX-License-Identifier: GPL-3.0-or-later
"""Tests of arlequin.load: reading series, breaks, summary, other CSVs and fields.h5."""

import json
import math
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import PYTHON_DIR

import arlequin


def test_load_reads_series_summary_and_other_csvs(results):
    folder = results.path
    (folder / "summary.json").write_text(json.dumps({"status": "ok", "steps": 40, "energy": None}))
    (folder / "sweep.csv").write_text("k,err\n1,0.5\n2,0.25\n")
    run = arlequin.load(folder)
    assert run.path == folder
    assert list(run.series.columns) == ["time", "step", "F_moved", "broken", "energy"]
    assert run.series["step"].tolist() == [0, 10, 20, 30, 40]
    assert run.series["F_moved"][2] == math.inf and run.series["broken"][3] == -math.inf
    assert math.isnan(run.series["broken"][1])
    assert run.summary == {"status": "ok", "steps": 40, "energy": None}
    assert run.breaks is None
    assert run.csv("sweep.csv")["err"].tolist() == [0.5, 0.25]


def test_load_reads_breaks_when_present(results):
    (results.path / "breaks.csv").write_text("time,set,bond,group,stress\n0.5,0,12,glue,1.5e9\n")
    breaks = arlequin.load(results.path).breaks
    assert breaks.to_dict("records") == [{"time": 0.5, "set": 0, "bond": 12, "group": "glue", "stress": 1.5e9}]


def test_absent_files_and_folder(tmp_path):
    run = arlequin.load(tmp_path)
    assert (run.series, run.breaks, run.summary) == (None, None, None)
    with pytest.raises(FileNotFoundError, match="fields.h5"):
        run.fields()
    with pytest.raises(FileNotFoundError, match="absent"):
        arlequin.load(tmp_path / "absent")


def test_fields_opens_hdf5_read_only(tmp_path):
    with h5py.File(tmp_path / "fields.h5", "w") as f:
        f["frame_0/u"] = np.arange(6.0).reshape(2, 3)
        f["frame_1/u"] = np.ones((2, 3))
        f["mesh/nodes"] = np.zeros((2, 3))
    run = arlequin.load(tmp_path)
    assert run.datasets() == ["frame_0/u", "frame_1/u", "mesh/nodes"]
    with run.fields() as f:
        assert f.mode == "r"
        np.testing.assert_array_equal(f["frame_0/u"][:], np.arange(6.0).reshape(2, 3))


def test_import_is_light():
    code = ("import sys, arlequin, arlequin.plot; "
            "print(sorted(m for m in ('numpy', 'pandas', 'h5py', 'matplotlib') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=PYTHON_DIR, timeout=60)
    assert done.stdout.strip() == "[]", done.stderr
