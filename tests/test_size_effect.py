"""Housner's size effect and the dimensionless collapse, on the stored study.

configs/size_effect.yaml sweeps geometrically similar rigid blocks (H/B = 4, heights 1-20 m)
under half-sine pulses. The similarity law says a block feels a pulse only through
A / (g tan alpha) and omega / p, and for the rigid RBM monolith (the linear model, alpha = B/H) the
minimum overturning amplitude in those axes is a closed form
(rbm_cli.structures.closed_forms.linear_halfsine_threshold, checked against an ODE bisection in
tests/test_closed_forms.py). So in dimensionless axes every size must fall on that one curve.
tests/test_regression.py re-makes the stored domain in CI; here it is checked against the
closed form.

Tolerance: the domain is sampled on an amplitude grid of step 0.025 g, 0.1 in A / (g tan alpha)
(tan alpha = 0.25): each boundary must bracket the exact threshold, so its spread about the
curve is at most one amplitude step. Stronger, and with no tolerance at all: every cell below
the curve survives and every cell above it collapses.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.config.types import G
from rbm_cli.structures.closed_forms import linear_halfsine_threshold
from rbm_cli.study.domain import read_domain

from .paths import CONFIGS, RESULTS

STUDY = RESULTS / "size_effect"
STEP_G = 0.025  # the study's amplitude step [g]
TAN_ALPHA = 0.25  # B / H


@pytest.fixture(scope="module")
def domain() -> pd.DataFrame:
    return read_domain(STUDY / "domain.csv")


def test_the_study_is_what_the_config_says(domain):
    cfg = load_config(CONFIGS / "size_effect.yaml")
    assert cfg.excitation.type == "half-sine" and cfg.interface.stiffness.kind == "rigid"
    sizes = np.unique(domain["column.size"])
    assert sizes.min() == 1.0 and sizes.max() == 20.0 and len(sizes) >= 8
    assert np.allclose(np.diff(np.log(sizes)), np.log(20.0) / (len(sizes) - 1))  # log axis


def test_the_scales_are_the_closed_form_of_the_rbm_block(domain):
    h = domain["column.size"].to_numpy()
    b = h / 4.0
    assert np.allclose(np.tan(domain["alpha_rad"]), TAN_ALPHA, rtol=1e-12)
    assert np.allclose(domain["p_rad_s"], np.sqrt(6 * G * h / (4 * h**2 + b**2)), rtol=1e-12)
    omega = 2 * math.pi * domain["frequency_hz"]
    assert np.allclose(domain["omega_over_p"], omega / domain["p_rad_s"], rtol=1e-12)
    assert np.allclose(domain["a_over_g_alpha"], domain["amplitude_g"] / TAN_ALPHA, rtol=1e-12)


def test_every_size_collapses_onto_the_exact_threshold(domain):
    exact = linear_halfsine_threshold(domain["omega_over_p"].to_numpy())
    ratio = domain["a_over_g_alpha"].to_numpy()
    collapsed = domain["collapsed"].to_numpy() == 1
    wrong = (ratio < exact) & collapsed | (ratio > exact) & ~collapsed
    assert not wrong.any(), domain[wrong].head()

    bnd = pd.read_csv(STUDY / "boundary.csv")
    scales = domain.groupby(["column.size", "frequency_hz"])["omega_over_p"].first()
    k = linear_halfsine_threshold(scales.to_numpy())
    low = bnd["lowest_unsafe_g"].to_numpy() / TAN_ALPHA
    high = bnd["highest_safe_g"].to_numpy() / TAN_ALPHA
    assert (high <= k).all() and (k <= low).all()
    spread = np.max(np.abs(low - k))
    assert spread <= STEP_G / TAN_ALPHA + 1e-12, spread


def test_the_larger_block_survives(domain):
    """Housner's size effect in physical units: at one pulse frequency, the overturning
    amplitude grows with the size of the block."""
    bnd = pd.read_csv(STUDY / "boundary.csv")
    for _, group in bnd.groupby("frequency_hz"):
        edge = group.sort_values("column.size")["lowest_unsafe_g"].to_numpy()
        assert np.all(np.diff(edge) >= 0.0) and edge[-1] > edge[0]
