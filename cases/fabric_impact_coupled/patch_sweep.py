# SPDX-License-Identifier: GPL-3.0-or-later
"""The coupled fabric impact against the pure-DEM run it replaces, over the DEM patch's size
(cases/fabric_impact_coupled/README.md): error against run time.

    build/app/arlequin run cases/fabric_impact/case.yaml --set "output.fields=[]" --out results/fabric_impact
    build/app/arlequin sweep cases/fabric_impact_coupled/case.yaml \\
        --over "coupling.overlap.shell.inner=[[0.007,0.021,-0.726e-3],[0.015,0.029,1.926e-3]],..." \\
        --with "coupling.overlap.shell.outer=[[0.006,0.020,-0.726e-3],[0.016,0.030,1.926e-3]],..." \\
        --set "output.fields=[]" --out results/fabric_impact_coupled_sweep
    PYTHONPATH=python python3 cases/fabric_impact_coupled/patch_sweep.py results/fabric_impact \\
        results/fabric_impact_coupled_sweep

For each run of the sweep: the DEM patch (its pure-DEM core, the overlap's inner box), its DEs and
the plate's nodes, the time loop's wall time, and against the pure-DEM run: the sphere's velocity
(the largest of |v / v_pure - 1| over the run: the issue's "max relative"), the peak impact force,
the first yarn break, the fracture energy and the largest energy imbalance. The pure run is the
table's first row. Prints a Markdown table and writes patch_sweep.csv and patch_sweep.png (velocity
error against wall time) into the sweep folder.
"""

import json
import sys
from pathlib import Path

import numpy as np

import arlequin

IMPACT_ENERGY = 2.557  # J, 1/2 m v^2 of the 5.43 mm steel sphere at 90 m/s (docs/validation.md#r8)


def patch_of(run):
    """The pure-DEM core's size along x and y, mm, from the resolved case's inner box (a flow list,
    which reads as JSON)."""
    for line in (run.path / "case.resolved.yaml").read_text().splitlines():
        if line.strip().startswith("inner:"):
            lower, upper = json.loads(line.split(":", 1)[1])
            return f"{(upper[0] - lower[0]) * 1e3:.0f} x {(upper[1] - lower[1]) * 1e3:.0f} mm"
    return run.path.name


def row_of(run, pure, label):
    s, summary = run.series, run.summary
    t = pure.series["time"].to_numpy()
    v_pure = pure.series["sphere_velocity"].to_numpy()
    v = np.interp(t, s["time"].to_numpy(), s["sphere_velocity"].to_numpy())
    peak, peak_pure = s["impact_force"].abs().max(), pure.series["impact_force"].abs().max()
    first, first_pure = summary.get("first_break_time", float("nan")), pure.summary.get("first_break_time", float("nan"))
    return {
        "run": label,
        "des": summary["counts"]["particles"],
        "nodes": summary["counts"].get("continuum_nodes", 0),
        "wall_s": summary["wall_time"]["time_loop"],
        "velocity_max_rel": float(np.max(np.abs(v / v_pure - 1.0))),
        "peak_force_rel": float(peak / peak_pure - 1.0),
        "first_break_rel": float(first / first_pure - 1.0),
        "fracture_J": float(s["E_fracture"].iloc[-1]),
        "balance_rel": float(s["E_balance"].abs().max() / IMPACT_ENERGY),
    }


def main(argv):
    if len(argv) != 3:
        raise SystemExit(__doc__)
    pure = arlequin.load(Path(argv[1]))
    sweep_dir = Path(argv[2])
    runs = arlequin.load_sweep(sweep_dir)
    rows = [row_of(pure, pure, "pure DEM")] + [row_of(r, pure, patch_of(r)) for r in runs]
    header = ["DEM core", "DEs", "plate nodes", "wall [s]", "speed-up", "velocity: max rel.", "peak force", "first break",
              "fracture energy [J]", "max |E_balance| / E_0"]
    print(arlequin.markdown_table(header, [
        [r["run"], r["des"], r["nodes"], f"{r['wall_s']:.1f}", f"{rows[0]['wall_s'] / r['wall_s']:.2f}x",
         f"{100 * r['velocity_max_rel']:.2f} %", f"{100 * r['peak_force_rel']:+.1f} %", f"{100 * r['first_break_rel']:+.1f} %",
         f"{r['fracture_J']:.4f}", f"{r['balance_rel']:.1e}"] for r in rows]))
    arlequin.write_table(sweep_dir / "patch_sweep.csv", rows)

    arlequin.plot_error_against_time(sweep_dir / "patch_sweep.png", rows[0], rows[1:],
                                     [("coupled", "velocity_max_rel", "o-")],
                                     "Coupled fabric impact against pure DEM, over the DEM patch",
                                     "sphere velocity: max |v / v_pure - 1| [%]")


if __name__ == "__main__":
    main(sys.argv)
