# SPDX-License-Identifier: GPL-3.0-or-later
"""The DCB arm's bending modulus from the virtual bending test arm_bending.yaml (README.md, "The
arms' bending modulus"):

    build/app/arlequin run cases/dcb/arm_bending.yaml
    PYTHONPATH=python python3 cases/dcb/arm_bending.py results/dcb_arm_bending

At the last field frame (the load held, the arm at rest) the script fits the cubic of
arlequin.cantilever_bending_modulus (between the load line and the clamp the deflection's third
derivative is P / (E I); the clamp's and the load line's exact positions do not enter) to the z
displacement of every DE whose reference centre lies in a window of the span, with P the load
line's force then and I = b h^3 / 12 of the arm's nominal section (b = 6 mm, h = 1.5 mm).
Windows: the span less 1.5 mm (one arm thickness, where the load's and the clamp's local fields
have decayed) at each end, and two narrower ones for the spread.
"""

import sys

import arlequin

SECOND_MOMENT = 6.0e-3 * 1.5e-3**3 / 12.0  # m^4, b h^3 / 12: the arm's width (y), thickness (z)
WINDOWS = ((1.5e-3, 12.0e-3), (2.0e-3, 11.0e-3), (3.0e-3, 10.0e-3))  # m, along x


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    run = arlequin.load(argv[1])
    with run.fields() as fields:
        last = fields["frames"][sorted(fields["frames"])[-1]]["particles"]
        position = last["points"][:]
        displacement = last["point/displacement"][:]
    reference_x = position[:, 0] - displacement[:, 0]
    load = run.series["P"].iloc[-1]
    print(f"load P = {load:.5g} N at Delta = {1e6 * run.series['Delta'].iloc[-1]:.4g} um")
    for window in WINDOWS:
        modulus = arlequin.cantilever_bending_modulus(reference_x, displacement[:, 2], load, SECOND_MOMENT, window)
        print(f"x in [{1e3 * window[0]:.1f}, {1e3 * window[1]:.1f}] mm: E_bending = {modulus / 1e9:.1f} GPa")


if __name__ == "__main__":
    main(sys.argv)
