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

The README's table sweeps following.yaml (the band that follows the crack) the same way, with
--over coupling.overlap.band.half_thickness=3.5e-4,5.0e-4,4.0e-4 --with
coupling.overlap.band.width=1.5e-4,2.0e-4,3.0e-4 and its own output.

(time.end = 2.1 ms: the load lines have opened by Delta = 2.0 mm, the end of the comparison.)
These sweep the case itself (40k DEs). Runs of the case made elsewhere (the validation tests'
pure DEM and coupled DCB, which run to the case's 2.6 ms) may stand in for the pure run and be
added after the sweep folder as further run folders. At 20k DEs (docs/decisions.md#d46) both
commands also take --set dem.sample.radius.mean=1.75e-4 --set dem.sample.file=$PWD/results/dcb_band_20k.h5
(one packing for all the runs: an absolute path, as a relative one is read from each case's own
folder), the pure run the 20k load lines, --set "groups=$G" with G the third entry of
cases/dcb/sweep_groups.txt, and the sweep the 20k arm's bending modulus, --set
continuum.material.E=9.8e10 (cases/dcb/README.md).

For each run: the band (half-thickness and overlap width, from its resolved case), the arms' mesh,
its DEs and the continuum's degrees of freedom, and its compute time (the time loop less its
output) brought to the earliest end time of the runs compared (a step costs about the same all
along a run), and against the pure-DEM run, over its rows with Delta in [0.5, 2.0] mm, the run's
load at their times (both impose the same Delta(t)): the load as docs/decisions.md#d51 compares it,
max |P - P_pure| / max P_pure, and row by row, max |P / P_pure - 1|; the peak load, and the
interface's dissipated energy at Delta = 2.0 mm; and P against LEFM (R5: the largest
|P / P_LEFM - 1| over Delta in [0.75, 2.0] mm, from the run's own check). The pure run is the
table's first row. Prints a Markdown table and writes band_sweep.csv and band_sweep.png (the load's
and the energy's difference against compute time) into the sweep folder.
"""

import sys
from pathlib import Path

import numpy as np

import arlequin

COMPARED = (0.5e-3, 2.0e-3)  # m, the Delta range of the comparison (the issue's)


def section_of(run, name):
    """The "key: value" entries directly under the first line "name:" of the run's resolved case
    (a block of indented lines; nested blocks' own entries left out), as strings; None if absent."""
    lines = (run.path / "case.resolved.yaml").read_text().splitlines()
    for k, line in enumerate(lines):
        if line.strip() == f"{name}:":
            indent = len(line) - len(line.lstrip())
            fields, child = {}, None
            for entry in lines[k + 1:]:
                depth = len(entry) - len(entry.lstrip())
                if depth <= indent:
                    break
                child = depth if child is None else child
                if depth == child and ":" in entry:
                    key, value = entry.strip().split(":", 1)
                    fields[key] = value.strip()
            return fields
    return None


def label_of(run):
    """"pure DEM", or the band's half-thickness / overlap width in mm, the arms' mesh (its file's
    name) and, if not fe, the solver."""
    band = section_of(run, "band")
    if band is None:
        return "pure DEM"
    label = f"{1e3 * float(band['half_thickness']):.2f} / {1e3 * float(band['width']):.2f} mm"
    label += ", " + Path(section_of(run, "mesh")["file"]).stem
    solver = section_of(run, "continuum")["solver"]
    return label if solver == "fe" else f"{label}, {solver}"


def lefm_error(run):
    """R5's P(Delta) check against LEFM over [0.75, 2.0] mm: the run's own figure (the case's check
    whose note says it)."""
    for check in run.summary.get("checks", []):
        if check.get("column") == "P" and "LEFM in propagation" in check.get("note", ""):
            return check["value"]
    return float("nan")


def compute_seconds(run, until):
    """The run's time loop less its output, brought from its end time to `until` (s)."""
    wall = run.summary["wall_time"]
    return (wall["time_loop"] - wall["output"]) * until / run.series["time"].iloc[-1]


def row_of(run, pure, until):
    s, p = run.series, pure.series
    inside = (p["Delta"] >= COMPARED[0]) & (p["Delta"] <= COMPARED[1])
    pure_load = p["P"][inside].to_numpy()
    load = np.interp(p["time"][inside].to_numpy(), s["time"].to_numpy(), s["P"].to_numpy())
    energy = np.interp(COMPARED[1], s["Delta"].to_numpy(), s["E_interface"].to_numpy())
    pure_energy = np.interp(COMPARED[1], p["Delta"].to_numpy(), p["E_interface"].to_numpy())
    counts = run.summary["counts"]
    return {
        "run": label_of(run),
        "des": counts["particles"],
        "continuum_dofs": 3 * counts.get("continuum_nodes", 0),
        "wall_s": compute_seconds(run, until),
        "P_rel": float(np.max(np.abs(load - pure_load)) / np.max(np.abs(pure_load))),
        "P_row_rel": float(np.max(np.abs(load / pure_load - 1.0))),
        "peak_rel": float(s[s["Delta"] <= COMPARED[1]]["P"].max() / p[p["Delta"] <= COMPARED[1]]["P"].max() - 1.0),
        "energy_rel": float(energy / pure_energy - 1.0),
        "lefm_max_rel": lefm_error(run),
    }


def main(argv):
    if len(argv) < 3:
        raise SystemExit(__doc__)
    pure = arlequin.load(Path(argv[1]))
    sweep_dir = Path(argv[2])
    loaded = arlequin.load_sweep(sweep_dir) + [arlequin.load(Path(a)) for a in argv[3:]]
    # A run that failed (damage reaching the overlap stops one) has no whole curve to compare:
    # it is listed below the table with its error, not left out silently.
    failed = [r for r in loaded if r.summary.get("status") == "failed"]
    runs = sorted((r for r in loaded if r not in failed), key=lambda r: (r.summary["counts"]["particles"], label_of(r)))
    until = min(r.series["time"].iloc[-1] for r in [pure] + runs)
    if pure.series["Delta"].max() < COMPARED[1] or until < pure.series["time"][pure.series["Delta"] <= COMPARED[1]].max():
        raise SystemExit(f"a run ends before Delta = {1e3 * COMPARED[1]:g} mm: run them to time.end = 2.1e-3 or later")
    rows = [row_of(pure, pure, until)] + [row_of(r, pure, until) for r in runs]
    header = ["band: half-thickness / overlap", "DEs", "continuum dofs", f"compute [s] to {1e3 * until:g} ms",
              "speed-up", "P: max diff. / max P_pure", "P: row by row", "peak load", "interface energy at 2 mm",
              "P vs LEFM (R5)"]
    print(arlequin.markdown_table(header, [
        [r["run"], r["des"], r["continuum_dofs"], f"{r['wall_s']:.0f}", f"{rows[0]['wall_s'] / r['wall_s']:.2f}x",
         f"{100 * r['P_rel']:.2f} %", f"{100 * r['P_row_rel']:.2f} %", f"{100 * r['peak_rel']:+.2f} %",
         f"{100 * r['energy_rel']:+.2f} %", f"{100 * r['lefm_max_rel']:.2f} %"] for r in rows]))
    for r in failed:
        print(f"{label_of(r)}: failed at t = {1e3 * r.series['time'].iloc[-1]:.3g} ms: {r.summary.get('error', '')}")
    arlequin.write_table(sweep_dir / "band_sweep.csv", rows)

    arlequin.plot_error_against_time(sweep_dir / "band_sweep.png", rows[0], rows[1:],
                                     [("coupled: P(Delta), max diff. / max P_pure", "P_rel", "o"),
                                      ("coupled: interface energy at 2 mm", "energy_rel", "s")],
                                     "Coupled DCB against pure DEM, over the DEM band", "|difference| from the pure DEM [%]",
                                     xlabel=f"compute time to t = {1e3 * until:g} ms (time loop less output) [s]")


if __name__ == "__main__":
    main(sys.argv)
