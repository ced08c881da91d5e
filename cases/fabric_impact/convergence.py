# SPDX-License-Identifier: GPL-3.0-or-later
"""Convergence of the fabric impact against run time (cases/fabric_impact/README.md).

    build/app/arlequin sweep cases/fabric_impact/case.yaml --over "dem.sample.chains=[3,1],[3,2],[6,2]" \
        --set "output.fields=[]" --out results/fabric_impact_convergence
    PYTHONPATH=python python3 cases/fabric_impact/convergence.py results/fabric_impact_convergence

Each run of the sweep is compared with the finest (the most DEs): the sphere's velocity history
(the largest difference over the run, over the impact speed 90 m/s), the time of the first
yarn break and the energy the broken springs took, against the run's wall time. Prints a
Markdown table and writes convergence.csv, convergence.png (difference against wall time) and
velocity.png (the histories) into the sweep folder.
"""

import sys
from pathlib import Path

import numpy as np

import arlequin

IMPACT_SPEED = 90.0  # m/s


def runs_of(sweep_dir):
    runs = [arlequin.load(p.parent) for p in sorted(Path(sweep_dir).glob("*/summary.json"))]
    if not runs:
        raise SystemExit(f"{sweep_dir}: no run folder (with summary.json) in it")
    return sorted(runs, key=lambda r: r.summary["counts"]["particles"])


def label_of(run):
    """The run's chains per yarn, from its resolved case (the sweep's axis)."""
    for line in (run.path / "case.resolved.yaml").read_text().splitlines():
        if line.strip().startswith("chains:"):
            return "chains " + line.split(":", 1)[1].strip()
    return run.path.name


def main(argv):
    if len(argv) != 2:
        raise SystemExit(__doc__)
    sweep_dir = Path(argv[1])
    runs = runs_of(sweep_dir)
    finest = runs[-1]
    t_ref = finest.series["time"].to_numpy()
    v_ref = finest.series["sphere_velocity"].to_numpy()
    rows = []
    for run in runs:
        s = run.series
        v = np.interp(t_ref, s["time"].to_numpy(), s["sphere_velocity"].to_numpy())
        summary = run.summary
        rows.append({
            "run": label_of(run),
            "des": summary["counts"]["particles"],
            "steps": summary["steps"],
            "wall_s": summary["wall_time"]["time_loop"],
            "max_dv_over_v0": float(np.max(np.abs(v - v_ref)) / IMPACT_SPEED),
            "v_end": float(s["sphere_velocity"].iloc[-1]),
            "first_break_us": summary.get("first_break_time", float("nan")) * 1e6,
            "fracture_J": float(s["E_fracture"].iloc[-1]),
            "worst_balance_J": float(s["E_balance"].abs().max()),
        })
    header = ["run", "DEs", "steps", "wall [s]", "max |v - v_finest| / 90 m/s", "v(100 us) [m/s]",
              "first break [us]", "fracture energy [J]", "max |E_balance| [J]"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        print(f"| {r['run']} | {r['des']} | {r['steps']} | {r['wall_s']:.1f} | {r['max_dv_over_v0']:.4f} | {r['v_end']:.2f} | "
              f"{r['first_break_us']:.1f} | {r['fracture_J']:.4f} | {r['worst_balance_J']:.2e} |")
    arlequin.write_table(sweep_dir / "convergence.csv", rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    coarse = rows[:-1]
    ax.loglog([r["wall_s"] for r in coarse], [r["max_dv_over_v0"] for r in coarse], "o-")
    for r in coarse:
        ax.annotate(f"{r['run']} ({r['des']} DEs)", (r["wall_s"], r["max_dv_over_v0"]), fontsize=8)
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("max |v - v_finest| / 90 m/s")
    ax.set_title(f"Fabric impact: sphere velocity against the finest ({finest.path.name}, {rows[-1]['wall_s']:.0f} s)")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(sweep_dir / "convergence.png", dpi=120)
    fig, ax = plt.subplots(figsize=(6, 4))
    for run, r in zip(runs, rows):
        ax.plot(run.series["time"] * 1e6, run.series["sphere_velocity"], label=f"{r['run']} ({r['des']} DEs)")
    ax.set_xlabel("time [us]")
    ax.set_ylabel("sphere velocity along z [m/s]")
    ax.legend()
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(sweep_dir / "velocity.png", dpi=120)


if __name__ == "__main__":
    main(sys.argv)
