# SPDX-License-Identifier: GPL-3.0-or-later
"""Draws the plots that a run describes in its plots.json, with matplotlib.

    python3 -m arlequin.plot RESULTS_DIR [--format png,svg,pdf] [--only FILE ...]

plots.json is the contract with the C++ program; python/README.md gives its format.
Reading and checking it needs only the standard library: numpy and matplotlib are
imported afterwards, so that a machine without them gets one line naming the skipped
plots (exit 3), which the C++ program relays.

Exit codes: 0 all drawn (or nothing to draw), 1 some plot failed, 2 bad input,
3 matplotlib or numpy missing.
"""

import argparse
import csv
import importlib
import json
import math
import os
import sys
from pathlib import Path

FORMATS = ("png", "svg", "pdf", "eps", "ps")
STYLES = {
    "line": {"linestyle": "-"},
    "points": {"linestyle": "none", "marker": "o", "markersize": 3},
    "line_points": {"linestyle": "-", "marker": "o", "markersize": 3},
    "dashed": {"linestyle": "--"},
}
FIGSIZE = (9.0, 5.6)  # inches; at DPI this is a 900 x 560 pixel PNG
DPI = 100
INSTALL_HINT = "install python3-matplotlib"


class InputError(ValueError):
    """Bad command-line input or plots.json; the message is the one line to print."""


class PlotError(ValueError):
    """One plot cannot be drawn; the others still are."""


# --- plots.json ----------------------------------------------------------------------------


def read_spec(path):
    """The list of plots in the plots.json at `path`, checked against the format."""
    try:
        spec = json.loads(Path(path).read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"plots.json: expected valid JSON ({e})") from None
    _expect(isinstance(spec, dict) and isinstance(spec.get("plots"), list), "top level",
            'an object with a "plots" list')
    for i, plot in enumerate(spec["plots"]):
        _check_plot(plot, f"plots[{i}]")
    return spec["plots"]


def _check_plot(plot, where):
    _expect(isinstance(plot, dict), where, "an object")
    file = plot.get("file")
    _expect(_is_plain_name(file) and Path(file).suffix[1:] in FORMATS, f"{where}.file",
            f"a file name in the results folder ending in .{', .'.join(FORMATS)}")
    where = f"{where} ({file})"
    for key in ("title", "x_label", "y_label", "y2_label"):
        _expect(isinstance(plot.get(key, ""), str), f"{where}.{key}", "a string")
    for key in ("log_x", "log_y", "log_y2"):
        _expect(isinstance(plot.get(key, False), bool), f"{where}.{key}", "true or false")
    _expect(isinstance(plot.get("series"), list), f"{where}.series", "a list")
    for j, series in enumerate(plot["series"]):
        _check_series(series, f"{where}.series[{j}]")


def _check_series(series, where):
    _expect(isinstance(series, dict), where, "an object")
    _expect(isinstance(series.get("label", ""), str), f"{where}.label", "a string")
    _expect(series.get("style", "line") in STYLES, f"{where}.style", " or ".join(f'"{s}"' for s in STYLES))
    _expect(isinstance(series.get("right_axis", False), bool), f"{where}.right_axis", "true or false")
    colour = series.get("colour", 0)
    _expect(isinstance(colour, int) and not isinstance(colour, bool) and colour >= 0, f"{where}.colour",
            "a whole number >= 0")
    from_csv = "csv" in series
    inline = "x_values" in series or "y_values" in series
    _expect(from_csv != inline, where, 'either "csv", "x", "y" or "x_values", "y_values"')
    if from_csv:
        _expect(_is_plain_name(series["csv"]), f"{where}.csv", "a file name in the results folder")
        for key in ("x", "y"):
            _expect(isinstance(series.get(key), str), f"{where}.{key}", "a column name")
        for key in ("x_scale", "y_scale"):
            _expect(_is_number(series.get(key, 1.0)), f"{where}.{key}", "a number")
    else:
        for key in ("x_values", "y_values"):
            values = series.get(key)
            _expect(isinstance(values, list) and all(v is None or _is_number(v) for v in values),
                    f"{where}.{key}", "a list of numbers (null for a missing value)")


def _expect(condition, where, what):
    if not condition:
        raise InputError(f"plots.json: {where}: expected {what}")


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_plain_name(name):
    return isinstance(name, str) and name not in ("", ".", "..") and "/" not in name and "\\" not in name


# --- drawing -------------------------------------------------------------------------------


def figure(results_dir, plot, tables=None):
    """The matplotlib Figure of one checked plot; CSVs are read from `results_dir`.

    `tables` caches the CSVs read (name -> columns) across the plots of one run.
    A series whose CSV or column is missing is left out with a warning on stderr.
    """
    from matplotlib import rcParams
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    tables = {} if tables is None else tables
    fig = Figure(figsize=FIGSIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    left = fig.add_subplot()
    right = left.twinx() if any(s.get("right_axis", False) for s in plot["series"]) else None
    log_x = plot.get("log_x", False)
    # Scales are set before plotting, so that a log axis left with no data still draws.
    if log_x:
        _log_scale(left.xaxis, left.set_xscale)
    if plot.get("log_y", False):
        _log_scale(left.yaxis, left.set_yscale)
    if right is not None and plot.get("log_y2", False):
        _log_scale(right.yaxis, right.set_yscale)
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    handles = []
    for j, series in enumerate(plot["series"]):
        on_right = series.get("right_axis", False)
        data = _series_data(Path(results_dir), plot, series, _series_name(j, series), tables)
        if data is None:
            continue
        x, y = _drop_unplottable(*data, log_x, plot.get("log_y2" if on_right else "log_y", False))
        label = series.get("label", "")
        colour = series.get("colour", len(handles))  # the cycle's next, unless the series names one
        (line,) = (right if on_right else left).plot(
            x, y, color=colours[colour % len(colours)], label=label or "_nolegend_",
            **STYLES[series.get("style", "line")])
        handles.append(line)
    left.set_title(plot.get("title", ""))
    left.set_xlabel(plot.get("x_label", ""))
    left.set_ylabel(plot.get("y_label", ""))
    left.grid(True, alpha=0.3)
    if right is not None:
        right.set_ylabel(plot.get("y2_label", ""))
    labelled = [h for h in handles if h.get_label() != "_nolegend_"]
    if labelled:
        (right or left).legend(labelled, [h.get_label() for h in labelled], loc="best")
    return fig


def _series_name(j, series):
    label = series.get("label", "")
    return f"series[{j}] ({label})" if label else f"series[{j}]"


def _series_data(results_dir, plot, series, name, tables):
    """(x, y) as float arrays, scaled; None (after a warning) if the CSV or a column is missing."""
    import numpy as np

    if "csv" not in series:
        x = np.array([math.nan if v is None else v for v in series["x_values"]], dtype=float)
        y = np.array([math.nan if v is None else v for v in series["y_values"]], dtype=float)
        if len(x) != len(y):
            raise PlotError(f"{name}: x_values has {len(x)} values but y_values has {len(y)}")
        return x, y
    file = series["csv"]
    if file not in tables:
        tables[file] = _read_csv(results_dir / file)
    columns = tables[file]
    missing = [series[key] for key in ("x", "y") if columns is not None and series[key] not in columns]
    if columns is None or missing:
        problem = "not found" if columns is None else f'has no column "{missing[0]}"'
        print(f'warning: {plot["file"]}: {file} {problem}; {name} left out', file=sys.stderr)
        return None
    x = _numbers(columns[series["x"]], file, series["x"], name) * series.get("x_scale", 1.0)
    y = _numbers(columns[series["y"]], file, series["y"], name) * series.get("y_scale", 1.0)
    return x, y


def _read_csv(path):
    """A CSV file as {column name: list of cell texts}, or None if it does not exist."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except FileNotFoundError:
        return None
    if not rows:
        return {}
    header, body = [name.strip() for name in rows[0]], rows[1:]
    return {name: [row[i] if i < len(row) else "" for row in body] for i, name in enumerate(header)}


def _numbers(cells, file, column, name):
    import numpy as np

    try:
        return np.array([float(c) if c.strip() else math.nan for c in cells], dtype=float)
    except ValueError as e:
        raise PlotError(f'{name}: column "{column}" of {file} is not numeric ({e})') from None


def _log_scale(axis, set_scale):
    """A log scale whose minor ticks are labelled too over spans of up to two decades, where the
    decades alone would leave one or two numbers on the axis."""
    from matplotlib.ticker import LogFormatterSciNotation

    set_scale("log")
    axis.set_minor_formatter(LogFormatterSciNotation(labelOnlyBase=False, minor_thresholds=(2, 0.5)))


def _drop_unplottable(x, y, log_x, log_y):
    """x, y with NaN where a point cannot be drawn, so the line breaks there."""
    import numpy as np

    keep = np.isfinite(x) & np.isfinite(y)
    if log_x:
        keep &= x > 0
    if log_y:
        keep &= y > 0
    return np.where(keep, x, math.nan), np.where(keep, y, math.nan)


def save(fig, path, fmt):
    """Writes `fig` to `path` atomically: to a temporary name beside it, then renamed."""
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        fig.savefig(temporary, format=fmt, dpi=DPI)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


# --- command line --------------------------------------------------------------------------


def _formats(text):
    formats = [f.strip().lower() for f in text.split(",")]
    if not all(f in FORMATS for f in formats):
        raise argparse.ArgumentTypeError(f"expected a comma list of {', '.join(FORMATS)}, got {text!r}")
    return formats


def _select(plots, only):
    if not only:
        return plots
    files = [plot["file"] for plot in plots]
    unknown = [name for name in only if name not in files]
    if unknown:
        raise InputError(f"--only: no plot {', '.join(unknown)} in plots.json (it has {', '.join(files) or 'none'})")
    return [plot for plot in plots if plot["file"] in only]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m arlequin.plot",
                                     description="Draw the plots described in RESULTS_DIR/plots.json.")
    parser.add_argument("results_dir", metavar="RESULTS_DIR")
    parser.add_argument("--format", type=_formats,
                        help="comma list of formats to draw each plot in (default: the extension of its file)")
    parser.add_argument("--only", nargs="+", metavar="FILE", help="draw only these plots (their \"file\")")
    args = parser.parse_args(argv)

    results = Path(args.results_dir)
    if not results.is_dir():
        print(f"{results}: no such results folder", file=sys.stderr)
        return 2
    if not (results / "plots.json").is_file():
        print(f"no plots.json in {results}: nothing to draw")
        return 0
    try:
        plots = _select(read_spec(results / "plots.json"), args.only)
    except InputError as e:
        print(e, file=sys.stderr)
        return 2
    if not plots:
        return 0
    try:
        for module in ("matplotlib", "numpy"):  # imported here to check; used by figure() and save()
            importlib.import_module(module)
    except ImportError as e:
        print(f"plots skipped ({', '.join(p['file'] for p in plots)}): {e}; {INSTALL_HINT}", file=sys.stderr)
        return 3

    tables = {}
    failed = False
    for plot in plots:
        file = Path(plot["file"])
        try:
            fig = figure(results, plot, tables)
            for fmt in args.format or [file.suffix[1:]]:
                path = results / file.with_suffix("." + fmt)
                save(fig, path, fmt)
                print(f"wrote {path}")
        except Exception as e:  # one bad plot must not stop the others
            reason = str(e) if isinstance(e, PlotError) else f"{type(e).__name__}: {e}"
            print(f"{plot['file']}: {' '.join(reason.split())}", file=sys.stderr)
            failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
