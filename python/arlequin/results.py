# SPDX-License-Identifier: GPL-3.0-or-later
"""Reading a results folder written by the arlequin C++ program into pandas, dicts and h5py.

    import arlequin
    run = arlequin.load("results/demo_beam_impact")
    run.series["F_moved"].plot()

pandas and h5py are imported only when a table or the fields file is first read.
"""

import json
from functools import cached_property
from pathlib import Path


class Run:
    """One results folder; tables are read on first access and then kept."""

    def __init__(self, path):
        self.path = Path(path)
        if not self.path.is_dir():
            raise FileNotFoundError(f"no results folder {self.path}")

    def __repr__(self):
        return f"Run({str(self.path)!r})"

    @cached_property
    def series(self):
        """series.csv as a DataFrame (one row per output time), or None if absent."""
        return self._optional_csv("series.csv")

    @cached_property
    def breaks(self):
        """breaks.csv as a DataFrame (one row per broken bond), or None if absent."""
        return self._optional_csv("breaks.csv")

    @cached_property
    def summary(self):
        """summary.json as a dict, or None if absent."""
        path = self.path / "summary.json"
        if not path.is_file():
            return None
        return json.loads(path.read_text(encoding="utf-8"))

    def csv(self, name):
        """Any CSV file of the folder (e.g. "sweep.csv") as a DataFrame."""
        import pandas

        return pandas.read_csv(self.path / name)

    def fields(self):
        """fields.h5 opened read-only as an h5py.File (use it in a `with` block)."""
        path = self.path / "fields.h5"
        if not path.is_file():
            raise FileNotFoundError(f"no fields file {path}")
        import h5py

        return h5py.File(path, "r")

    def datasets(self):
        """Paths of all datasets in fields.h5 (e.g. "frame_0/u"), in the order h5py visits them."""
        import h5py

        names = []
        with self.fields() as f:
            f.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
        return names

    def _optional_csv(self, name):
        return self.csv(name) if (self.path / name).is_file() else None


def load(path):
    """The results folder at `path` as a Run; FileNotFoundError if it is not a folder."""
    return Run(path)


def write_table(path, rows):
    """Rows (dicts with the same keys, in order) as a CSV file at `path`: the keys as its header."""
    with open(path, "w") as out:
        out.write(",".join(rows[0].keys()) + "\n")
        for r in rows:
            out.write(",".join(str(v) for v in r.values()) + "\n")

