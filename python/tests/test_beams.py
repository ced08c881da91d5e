# SPDX-License-Identifier: GPL-3.0-or-later
"""Tests of arlequin.cantilever_bending_modulus against closed-form cantilever deflections."""

import numpy as np
import pytest

import arlequin

E = 110.0e9  # Pa
NU = 0.24
B, H = 6.0e-3, 1.5e-3  # m, the section
I = B * H**3 / 12.0
L = 13.5e-3  # m, load at x = 0, clamp at x = L
P = 4.4  # N


def timoshenko_deflection(x):
    """Tip-loaded cantilever clamped at x = L, loaded at x = 0: bending plus shear (k = 5/6)."""
    shear_modulus = E / (2.0 * (1.0 + NU))
    bending = P / (6.0 * E * I) * (2.0 * L**3 - 3.0 * L**2 * x + x**3)
    shear = P * (L - x) / (5.0 / 6.0 * shear_modulus * B * H)
    return bending + shear


def test_recovers_the_modulus_with_shear_and_an_unknown_clamp_position():
    x = np.linspace(0.0, L, 4000)
    w = timoshenko_deflection(x) + 1.0e-7  # a rigid offset: the fit must not see it
    modulus = arlequin.cantilever_bending_modulus(x, w, P, I, (1.5e-3, 12.0e-3))
    assert modulus == pytest.approx(E, rel=1e-9)


def test_scatter_about_the_deflection_averages_out():
    rng = np.random.default_rng(3)
    x = rng.uniform(0.0, L, 4000)
    w = timoshenko_deflection(x)
    noisy = w + rng.normal(0.0, 0.002 * w.max(), x.size)  # 0.2 % of the tip deflection per point
    modulus = arlequin.cantilever_bending_modulus(x, noisy, P, I, (1.5e-3, 12.0e-3))
    # This draw lands 0.33 % off; the bound leaves three times that.
    assert modulus == pytest.approx(E, rel=0.01)


def test_a_window_with_too_few_points_is_refused():
    x = np.linspace(0.0, L, 20)
    with pytest.raises(ValueError, match="too few"):
        arlequin.cantilever_bending_modulus(x, timoshenko_deflection(x), P, I, (5.0e-3, 6.0e-3))
