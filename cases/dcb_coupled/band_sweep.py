# SPDX-License-Identifier: GPL-3.0-or-later
"""The coupled DCB against the pure-DEM DCB it replaces, over the DEM band's half-thickness and its
overlap's width (cases/dcb_coupled/README.md): error against run time.

    build/app/arlequin run cases/dcb/case.yaml --set time.end=2.1e-3 --set "output.fields=[]" \\
        --out results/dcb_band_pure
    build/app/arlequin sweep cases/dcb_coupled/case.yaml \\
        --over coupling.overlap.band.half_thickness=5.0e-4,7.5e-4,1.0e-3,7.5e-4 \\
        --with coupling.overlap.band.width=2.5e-4,2.5e-4,2.5e-4,5.0e-4 \\
        --set time.end=2.1e-3 --set "output.fields=[]" --out results/dcb_band_sweep
    PYTHONPATH=python python3 cases/dcb_coupled/band_sweep.py results/dcb_band_pure results/dcb_band_sweep

(time.end = 2.1 ms: the load lines have opened by Delta = 2.0 mm, the end of the comparison.)
These sweep the case itself (40k DEs). The README's table is at 20k (docs/decisions.md#d46): both
commands also take --set dem.sample.radius.mean=1.75e-4 --set dem.sample.file=$PWD/results/dcb_band_20k.h5
(one packing for all the runs: an absolute path, as a relative one is read from each case's own
folder), the pure run the 20k load lines, --set "groups=$G" with G the third
entry of cases/dcb/sweep_groups.txt, and the sweep --set coupling.continuum_substeps=3 and the
20k arm's bending modulus, --set continuum.material.E=9.8e10 (cases/dcb/README.md; the README's
table was measured before the case took the arms' bending modulus, at 135 GPa, and with P1 arms:
--set continuum.mesh.file=../../meshes/dcb_arms.geo --set continuum.mesh.order=1 reproduces them;
docs/decisions.md#d47, #d48).
For each run: the band (half-thickness and overlap width, from its resolved case), its DEs and the
continuum's degrees of freedom, the time loop's wall time, and against the pure-DEM run: P(Delta)
(the largest |P / P_pure - 1| over Delta in [0.5, 2.0] mm, P_pure interpolated at the run's
Delta), the peak load, and the interface's dissipated energy at Delta = 2.0 mm; and P against
LEFM (R5: the largest |P / P_LEFM - 1| over Delta in [0.75, 2.0] mm, from the run's own check).
The pure run is the table's first row. Prints a Markdown table and writes band_sweep.csv and
band_sweep.png (P error against wall time) into the sweep folder.
"""

import sys
from pathlib import Path

import numpy as np

import arlequin

COMPARED = (0.5e-3, 2.0e-3)  # m, the Delta range of the comparison (the issue's)


def band_of(run):
    """(half-thickness, overlap width) of the band in mm, from the resolved case's band entry (a
    block of indented "key: value" lines); None for a run without a band."""
    lines = (run.path / "case.resolved.yaml").read_text().splitlines()
    for k, line in enumerate(lines):
        if line.strip() == "band:":
            indent = len(line) - len(line.lstrip())
            fields = {}
            for entry in lines[k + 1:]:
                if len(entry) - len(entry.lstrip()) <= indent:
                    break
                key, value = entry.strip().split(":", 1)
                fields[key] = value.strip()
            return 1e3 * float(fields["half_thickness"]), 1e3 * float(fields["width"])
    return None


def lefm_error(run):
    """R5's P(Delta) check against LEFM over [0.75, 2.0] mm: the run's own figure (the case's check
    whose note says it)."""
    for check in run.summary.get("checks", []):
        if check.get("column") == "P" and "LEFM in propagation" in check.get("note", ""):
            return check["value"]
    return float("nan")


def row_of(run, pure):
    s, p = run.series, pure.series
    delta, load = s["Delta"].to_numpy(), s["P"].to_numpy()
    inside = (delta >= COMPARED[0]) & (delta <= COMPARED[1])
    pure_load = np.interp(delta[inside], p["Delta"].to_numpy(), p["P"].to_numpy())
    energy = np.interp(COMPARED[1], delta, s["E_interface"].to_numpy())
    pure_energy = np.interp(COMPARED[1], p["Delta"].to_numpy(), p["E_interface"].to_numpy())
    counts = run.summary["counts"]
    band = band_of(run)
    return {
        "run": "pure DEM" if band is None else f"{band[0]:.2f} / {band[1]:.2f} mm",
        "des": counts["particles"],
        "continuum_dofs": 3 * counts.get("continuum_nodes", 0),
        "wall_s": run.summary["wall_time"]["time_loop"],
        "P_max_rel": float(np.max(np.abs(load[inside] / pure_load - 1.0))),
        "peak_rel": float(s[s["Delta"] <= COMPARED[1]]["P"].max() / p[p["Delta"] <= COMPARED[1]]["P"].max() - 1.0),
        "energy_rel": float(energy / pure_energy - 1.0),
        "lefm_max_rel": lefm_error(run),
    }


def main(argv):
    if len(argv) != 3:
        raise SystemExit(__doc__)
    pure = arlequin.load(Path(argv[1]))
    sweep_dir = Path(argv[2])
    runs = arlequin.load_sweep(sweep_dir)
    rows = [row_of(pure, pure)] + [row_of(r, pure) for r in runs]
    header = ["band: half-thickness / overlap", "DEs", "continuum dofs", "wall [s]", "speed-up",
              "P: max rel. over [0.5, 2] mm", "peak load", "interface energy at 2 mm", "P vs LEFM (R5)"]
    print(arlequin.markdown_table(header, [
        [r["run"], r["des"], r["continuum_dofs"], f"{r['wall_s']:.0f}", f"{rows[0]['wall_s'] / r['wall_s']:.2f}x",
         f"{100 * r['P_max_rel']:.1f} %", f"{100 * r['peak_rel']:+.1f} %", f"{100 * r['energy_rel']:+.1f} %",
         f"{100 * r['lefm_max_rel']:.1f} %"] for r in rows]))
    arlequin.write_table(sweep_dir / "band_sweep.csv", rows)

    arlequin.plot_error_against_time(sweep_dir / "band_sweep.png", rows[0], rows[1:],
                                     [("coupled: P(Delta)", "P_max_rel", "o"),
                                      ("coupled: interface energy at 2 mm", "energy_rel", "s")],
                                     "Coupled DCB against pure DEM, over the DEM band", "|difference| from the pure DEM [%]")


if __name__ == "__main__":
    main(sys.argv)
