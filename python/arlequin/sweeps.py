# SPDX-License-Identifier: GPL-3.0-or-later
"""A coupled case's sweep against the pure-DEM run it replaces: its runs, and the error against run
time plot (the case scripts cases/*/..._sweep.py build their rows, then call these)."""

from pathlib import Path

from .results import load


def load_sweep(folder):
    """The runs of a sweep folder (each sub-folder with a summary.json), fewest DEs first;
    FileNotFoundError naming the folder if it has none."""
    folder = Path(folder)
    runs = [load(p.parent) for p in sorted(folder.glob("*/summary.json"))]
    if not runs:
        raise FileNotFoundError(f"{folder}: no run folder (with summary.json) in it")
    return sorted(runs, key=lambda r: r.summary["counts"]["particles"])


def markdown_table(header, rows):
    """A Markdown table (a string, one line per row) of `header` and `rows` (lists of cells)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def plot_error_against_time(path, pure, coupled, curves, title, ylabel, gate=5.0,
                            xlabel="wall time of the run's time loop [s]"):
    """Draws, for each of `curves` ((legend, key, marker) triples), the coupled rows' row[key] in
    per cent against their wall time (row["wall_s"]), each point of the first curve annotated with
    its row["run"] and row["des"]; the pure row's wall time as a dashed line and `gate` per cent as
    a dotted one; `xlabel` says what the wall times are. Saves the figure at `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    wall = [r["wall_s"] for r in coupled]
    for legend, key, marker in curves:
        ax.plot(wall, [100 * abs(r[key]) for r in coupled], marker, label=legend)
    first_key = curves[0][1]
    for r in coupled:
        ax.annotate(f"{r['run']} ({r['des']} DEs)", (r["wall_s"], 100 * abs(r[first_key])), fontsize=8)
    ax.axvline(pure["wall_s"], color="k", ls="--", label=f"pure DEM ({pure['des']} DEs)")
    ax.axhline(gate, color="r", ls=":", label=f"{gate:g} %")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
