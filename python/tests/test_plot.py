# SPDX-License-Identifier: GPL-3.0-or-later
"""Tests of arlequin.plot: the plots.json contract, the drawn data and the command line."""

import math
import struct

import numpy as np
import pytest
from conftest import run_plot
from matplotlib.colors import to_hex
from matplotlib.image import imread

from arlequin import plot

NAN = math.nan
TIME = [0, 0.5, 1, 1.5, 2]  # the columns of conftest.SERIES_CSV
F_MOVED = [0, 2, math.inf, 4, 5]
BROKEN = [0, NAN, 5, -math.inf, 10]
ENERGY = [1, -1, 0, 2, 4]


def csv_series(y, **more):
    return {"csv": "series.csv", "x": "time", "y": y, **more}


def lines_of(fig):
    """Every line of the figure as (label, x, y, axes index), left axis first."""
    return [(line.get_label(), line.get_xdata(), line.get_ydata(), i)
            for i, ax in enumerate(fig.axes) for line in ax.get_lines()]


def legend_of(fig):
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    assert len(legends) == 1
    return legends[0]


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


# --- drawn data ----------------------------------------------------------------------------


def test_lines_hold_exactly_the_scaled_data(results):
    spec = {"file": "a.png", "series": [csv_series("energy", label="E", x_scale=10, y_scale=-0.5)]}
    [(label, x, y, axis)] = lines_of(plot.figure(results.path, spec))
    assert (label, axis) == ("E", 0)
    np.testing.assert_array_equal(x, [0, 5, 10, 15, 20])
    np.testing.assert_array_equal(y, [-0.5, 0.5, 0, -1, -2])


def test_non_finite_points_become_gaps(results):
    spec = {"file": "a.png", "series": [csv_series("F_moved"), csv_series("broken")]}
    [(_, x1, y1, _), (_, x2, y2, _)] = lines_of(plot.figure(results.path, spec))
    np.testing.assert_array_equal(x1, [0, 0.5, NAN, 1.5, 2])
    np.testing.assert_array_equal(y1, [0, 2, NAN, 4, 5])
    np.testing.assert_array_equal(x2, [0, NAN, 1, NAN, 2])
    np.testing.assert_array_equal(y2, [0, NAN, 5, NAN, 10])


def test_log_axes_skip_non_positive_values(results):
    spec = {"file": "a.png", "log_x": True, "log_y2": True, "series": [
        csv_series("energy"),                                   # left axis stays linear
        csv_series("energy", right_axis=True),                  # right axis is log
    ]}
    fig = plot.figure(results.path, spec)
    left, right = fig.axes
    assert (left.get_xscale(), left.get_yscale(), right.get_yscale()) == ("log", "linear", "log")
    [(_, x1, y1, _), (_, x2, y2, _)] = lines_of(fig)
    np.testing.assert_array_equal(x1, [NAN, 0.5, 1, 1.5, 2])    # time 0 is not on a log axis
    np.testing.assert_array_equal(y1, [NAN, -1, 0, 2, 4])
    np.testing.assert_array_equal(x2, [NAN, NAN, NAN, 1.5, 2])
    np.testing.assert_array_equal(y2, [NAN, NAN, NAN, 2, 4])


def test_a_log_axis_within_two_decades_labels_more_than_its_decades(results):
    # 0.015 .. 0.13 holds one power of ten: without labelled minor ticks the axis shows one number.
    spec = {"file": "a.png", "log_y": True, "series": [{"x_values": [1, 2, 3], "y_values": [0.13, 0.045, 0.015]}]}
    fig = plot.figure(results.path, spec)
    fig.canvas.draw()
    axis = fig.axes[0].yaxis
    labels = [t.get_text() for t in axis.get_majorticklabels() + axis.get_minorticklabels()
              if t.get_text() and 0.015 <= t.get_position()[1] <= 0.13]
    assert len(labels) >= 4, labels


def test_log_axes_without_plottable_data_still_draw(results, tmp_path):
    spec = {"file": "a.png", "log_x": True, "log_y": True, "log_y2": True, "series": [
        {"x_values": [0, -1], "y_values": [1, 2]}, csv_series("broken", y_scale=-1, right_axis=True)]}
    plot.save(plot.figure(results.path, spec), tmp_path / "a.png", "png")
    assert png_size(tmp_path / "a.png") == (900, 560)


def test_legend_has_both_axes_and_colours_differ(results):
    spec = {"file": "a.png", "y2_label": "broken %", "series": [
        csv_series("F_moved", label="force"),
        csv_series("broken", label="broken", right_axis=True),
        csv_series("energy", label=""),                         # drawn, not in the legend
        {"label": "fit", "x_values": [0, 1], "y_values": [1, 2], "right_axis": True},
    ]}
    fig = plot.figure(results.path, spec)
    legend = legend_of(fig)
    assert legend.axes is fig.axes[-1]                          # on the right axis, above all lines
    assert [t.get_text() for t in legend.get_texts()] == ["force", "broken", "fit"]
    colours = [line.get_color() for ax in fig.axes for line in ax.get_lines()]
    assert len(colours) == 4 and len(set(colours)) == 4
    from matplotlib import rcParams
    cycle = rcParams["axes.prop_cycle"].by_key()["color"]
    # the cycle goes on across both axes in the order of the series
    assert [to_hex(c) for c in colours] == [to_hex(c) for c in (cycle[0], cycle[2], cycle[1], cycle[3])]
    assert fig.axes[1].get_ylabel() == "broken %"


def test_a_named_colour_overrides_the_cycle(results):
    spec = {"file": "a.png", "series": [
        csv_series("energy", label="a"), csv_series("energy", label="b"),
        csv_series("energy", colour=0, style="dashed"), csv_series("energy", colour=11)]}
    fig = plot.figure(results.path, spec)
    from matplotlib import rcParams
    cycle = rcParams["axes.prop_cycle"].by_key()["color"]
    colours = [to_hex(line.get_color()) for line in fig.axes[0].get_lines()]
    assert colours == [to_hex(c) for c in (cycle[0], cycle[1], cycle[0], cycle[11 % len(cycle)])]


def test_labels_title_and_styles(results):
    spec = {"file": "a.png", "title": "Tension", "x_label": "strain", "y_label": "stress GPa", "series": [
        csv_series("energy", style="points"), csv_series("energy", style="line_points"), csv_series("energy")]}
    fig = plot.figure(results.path, spec)
    [ax] = fig.axes                                             # no right axis without a right series
    assert (ax.get_title(), ax.get_xlabel(), ax.get_ylabel()) == ("Tension", "strain", "stress GPa")
    styles = [(line.get_linestyle(), line.get_marker()) for line in ax.get_lines()]
    assert styles == [("None", "o"), ("-", "o"), ("-", "None")]
    assert ax.get_legend() is None


def test_inline_data_with_nulls(results):
    spec = {"file": "a.png", "series": [{"label": "fit", "x_values": [1, None, 3, 4], "y_values": [5, 6, None, 8]}]}
    [(label, x, y, _)] = lines_of(plot.figure(results.path, spec))
    assert label == "fit"
    np.testing.assert_array_equal(x, [1, NAN, NAN, 4])
    np.testing.assert_array_equal(y, [5, NAN, NAN, 8])


def test_missing_column_warns_once_and_draws_the_rest(results, capsys):
    spec = {"file": "a.png", "series": [csv_series("F_moved", label="F"), csv_series("nope", label="gone")]}
    assert [label for label, *_ in lines_of(plot.figure(results.path, spec))] == ["F"]
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "a.png" in err[0] and "series.csv" in err[0] and '"nope"' in err[0]


def test_non_numeric_column_fails_the_plot(results):
    (results.path / "breaks.csv").write_text("time,group\n0.5,glue\n")
    spec = {"file": "a.png", "series": [{"csv": "breaks.csv", "x": "time", "y": "group"}]}
    with pytest.raises(plot.PlotError, match='series\\[0\\]: column "group" of breaks.csv is not numeric'):
        plot.figure(results.path, spec)


# --- command line --------------------------------------------------------------------------


def test_command_writes_a_valid_png_of_the_expected_size(results):
    folder = results({"file": "failure.png", "title": "t", "series": [csv_series("F_moved", label="F")]})
    done = run_plot(folder)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"wrote {folder}/failure.png"]
    assert png_size(folder / "failure.png") == (900, 560)
    assert imread(folder / "failure.png").shape[:2] == (560, 900)   # decodes completely
    assert sorted(p.name for p in folder.iterdir()) == ["failure.png", "plots.json", "series.csv"]  # no temp file


def test_command_missing_column_still_draws(results):
    folder = results({"file": "a.png", "series": [csv_series("F_moved"), csv_series("nope")]})
    done = run_plot(folder)
    assert done.returncode == 0
    [line] = done.stderr.splitlines()
    assert "a.png" in line and "series.csv" in line and '"nope"' in line
    assert (folder / "a.png").is_file()


def test_bad_inline_series_fails_only_its_plot(results):
    folder = results({"file": "bad.png", "series": [{"label": "fit", "x_values": [1, 2], "y_values": [1]}]},
                     {"file": "good.png", "series": [csv_series("energy")]})
    done = run_plot(folder)
    assert done.returncode == 1
    [line] = done.stderr.splitlines()
    assert line.startswith("bad.png: series[0] (fit):")
    assert done.stdout.splitlines() == [f"wrote {folder}/good.png"]
    assert not (folder / "bad.png").exists()


def test_formats_option_writes_each_format(results):
    folder = results({"file": "a.png", "series": [csv_series("energy")]})
    done = run_plot(folder, "--format", "svg,pdf")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"wrote {folder}/a.svg", f"wrote {folder}/a.pdf"]
    assert (folder / "a.svg").read_text().lstrip().startswith("<?xml")
    assert (folder / "a.pdf").read_bytes().startswith(b"%PDF")
    assert sorted(p.name for p in folder.iterdir()) == ["a.pdf", "a.svg", "plots.json", "series.csv"]


def test_only_option(results):
    folder = results({"file": "a.png", "series": []}, {"file": "b.svg", "series": []})
    done = run_plot(folder, "--only", "b.svg")
    assert done.returncode == 0 and done.stdout.splitlines() == [f"wrote {folder}/b.svg"]
    done = run_plot(folder, "--only", "c.png")
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1 and "c.png" in done.stderr


def test_unknown_format_exits_2(results):
    folder = results({"file": "a.png", "series": []})
    done = run_plot(folder, "--format", "png,gif")
    assert done.returncode == 2 and "gif" in done.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["plots.json", "series.csv"]


@pytest.mark.parametrize("text", [
    "{not json",
    '[{"file": "a.png"}]',
    '{"plots": {}}',
    '{"plots": [{"series": []}]}',
    '{"plots": [{"file": "../a.png", "series": []}]}',
    '{"plots": [{"file": "a.txt", "series": []}]}',
    '{"plots": [{"file": "a.png"}]}',
    '{"plots": [{"file": "a.png", "log_y": "yes", "series": []}]}',
    '{"plots": [{"file": "a.png", "series": [{"label": "no data"}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"csv": "s.csv", "x": "t", "y": "u", "x_values": [1]}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"csv": "s.csv", "x": "t"}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"csv": "s.csv", "x": "t", "y": "u", "y_scale": "2"}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"x_values": [1], "y_values": ["1"]}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"x_values": [1], "y_values": [1], "style": "bars"}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"x_values": [1], "y_values": [1], "colour": -1}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"x_values": [1], "y_values": [1], "colour": "C0"}]}]}',
    '{"plots": [{"file": "a.png", "series": [{"x_values": [1], "y_values": [1], "colour": true}]}]}',
])
def test_bad_plots_json_exits_2_with_one_line(results, text):
    (results.path / "plots.json").write_text(text)
    done = run_plot(results.path)
    assert done.returncode == 2
    [line] = done.stderr.splitlines()
    assert line.startswith("plots.json: ") and "expected" in line
    assert done.stdout == ""


def test_missing_folder_exits_2_and_no_plots_json_exits_0(tmp_path):
    done = run_plot(tmp_path / "absent")
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1
    done = run_plot(tmp_path)
    assert done.returncode == 0 and len(done.stdout.splitlines()) == 1 and "plots.json" in done.stdout
    assert list(tmp_path.iterdir()) == []


BLOCK_AND_RUN = """
import importlib.abc, runpy, sys
class Blocker(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("matplotlib", "numpy", "pandas"):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
sys.meta_path.insert(0, Blocker())
sys.argv[0] = "plot"
runpy.run_module("arlequin.plot", run_name="__main__")
"""


def test_without_matplotlib_exits_3_with_one_line(results):
    folder = results({"file": "failure.png", "series": [csv_series("F_moved")]},
                     {"file": "energy.svg", "series": [csv_series("energy")]})
    done = run_plot(folder, python_code=BLOCK_AND_RUN)
    assert done.returncode == 3
    assert done.stderr == ("plots skipped (failure.png, energy.svg): No module named 'matplotlib'; "
                           "install python3-matplotlib\n")
    assert done.stdout == ""
    assert sorted(p.name for p in folder.iterdir()) == ["plots.json", "series.csv"]


def test_shadowed_matplotlib_exits_3(results, tmp_path):
    fake = tmp_path / "fake" / "matplotlib"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('matplotlib is broken here')\n")
    folder = results({"file": "a.png", "series": []})
    done = run_plot(folder, extra_path=[fake.parent])
    assert done.returncode == 3
    assert done.stderr == "plots skipped (a.png): matplotlib is broken here; install python3-matplotlib\n"


# --- atomic write --------------------------------------------------------------------------


def test_failed_save_keeps_the_old_file_and_leaves_no_temp_file(results, monkeypatch):
    fig = plot.figure(results.path, {"file": "a.png", "series": [csv_series("energy")]})
    target = results.path / "a.png"
    target.write_bytes(b"old")

    def half_write_then_fail(path, **kwargs):
        with open(path, "wb") as f:
            f.write(b"partial")
        raise OSError("disk full")

    monkeypatch.setattr(fig, "savefig", half_write_then_fail)
    with pytest.raises(OSError):
        plot.save(fig, target, "png")
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in results.path.iterdir()) == ["a.png", "series.csv"]

