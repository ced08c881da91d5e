# SPDX-License-Identifier: GPL-3.0-or-later
"""Beam theory for reading virtual bending tests."""


def cantilever_bending_modulus(x, w, load, second_moment, window):
    """Young's modulus E [Pa] of a cantilever under an end load, from its deflection.

    Between the load and the clamp the bending moment is P (x - x_P), so the Euler-Bernoulli
    deflection is a cubic with w''' = P / (E I); shear deformation adds a term linear in x, which
    the cubic absorbs, and neither the clamp's nor the load's position enters. Fits
    w = c0 + c1 x + c2 x^2 + c3 x^3 by least squares to the points with window[0] < x < window[1]
    and returns load / (6 second_moment |c3|).

    x: positions along the beam (m), w: deflections there (m), load: P (N), second_moment: I of
    the section (m^4), window: (x_lo, x_hi) (m), inside the span, away from its ends.
    """
    import numpy as np

    x = np.asarray(x, dtype=float)
    w = np.asarray(w, dtype=float)
    inside = (x > window[0]) & (x < window[1])
    if inside.sum() < 8:
        raise ValueError(f"{inside.sum()} points in the window {window} m: too few to fit a cubic")
    cubic = np.polyfit(x[inside], w[inside], 3)[0]
    return load / (6.0 * second_moment * abs(cubic))
