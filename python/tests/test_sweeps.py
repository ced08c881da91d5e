# SPDX-License-Identifier: GPL-3.0-or-later
"""Tests of arlequin.load_sweep, markdown_table and plot_error_against_time."""

import json

import pytest

import arlequin


def _run(folder, particles):
    folder.mkdir()
    (folder / "summary.json").write_text(json.dumps({"counts": {"particles": particles}}))


def test_load_sweep_takes_the_runs_fewest_des_first(tmp_path):
    _run(tmp_path / "0", 300)
    _run(tmp_path / "1", 100)
    _run(tmp_path / "2", 200)
    (tmp_path / "not_a_run").mkdir()  # no summary.json: not a run
    runs = arlequin.load_sweep(tmp_path)
    assert [r.path.name for r in runs] == ["1", "2", "0"]


def test_load_sweep_of_a_folder_without_runs(tmp_path):
    with pytest.raises(FileNotFoundError, match="no run folder"):
        arlequin.load_sweep(tmp_path)


def test_error_against_time_plot_is_written(tmp_path):
    pure = {"run": "pure DEM", "des": 1000, "wall_s": 10.0, "error": 0.0}
    coupled = [{"run": "a", "des": 300, "wall_s": 3.0, "error": 0.04}, {"run": "b", "des": 500, "wall_s": 5.0, "error": -0.02}]
    path = tmp_path / "sweep.png"
    arlequin.plot_error_against_time(path, pure, coupled, [("coupled", "error", "o")], "title", "error [%]")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_markdown_table():
    assert arlequin.markdown_table(["a", "b"], [[1, "x"], [2.5, "y"]]) == "| a | b |\n|---|---|\n| 1 | x |\n| 2.5 | y |"
