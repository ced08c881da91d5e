# SPDX-License-Identifier: GPL-3.0-or-later
"""Python side of arlequin: read a run's results folder and draw its plots.

`arlequin.load(path)` gives the run's tables and fields; `python3 -m arlequin.plot DIR`
draws the plots that the C++ program describes in DIR/plots.json. Importing this package
is cheap: numpy, pandas, h5py and matplotlib are imported only when first needed.
"""

from .beams import cantilever_bending_modulus
from .results import Run, load, write_table
from .sweeps import load_sweep, markdown_table, plot_error_against_time

__all__ = [
    "Run",
    "load",
    "write_table",
    "load_sweep",
    "markdown_table",
    "plot_error_against_time",
    "cantilever_bending_modulus",
]
