"""The law pieces of the compiled integrators (rbm_cli.models.rbm.pieces) against the Python
bookkeeping of tests/piece_oracle.py (Pieces), the laws' potential
(Law.potential), the shear ratios and the energy of the model (structures/equations); and the
compiled functions against their uncompiled versions, bit for bit."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.base.events import BIG, EVENT_EPS
from rbm_cli.base.jit import plain
from rbm_cli.config.load import load_config
from rbm_cli.models.rbm import pieces as compiled
from rbm_cli.structures.arrays import rest_levels
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.law import law_arrays

from .paths import CONFIGS
from .piece_oracle import Pieces

KINDS = {compiled.UPLIFT: "uplift", compiled.KINK: "kink", compiled.IMPACT: "impact"}


def _model(name: str, **interface):
    cfg = load_config(CONFIGS / f"{name}.yaml")
    if interface:
        cfg = dataclasses.replace(cfg, interface=dataclasses.replace(cfg.interface, **interface))
    return model_from_config(cfg)


MODELS = {
    "8 drums, bilinear": lambda: _model("ci/harmonic_multidrum_ci"),
    "8 drums, tri-linear, e < 1": lambda: _model(
        "ci/harmonic_multidrum_ci", xi=0.6, restitution=0.9
    ),
    "rigid block": lambda: _model("spanos_koh_slender"),
}


def _walk(model, fns, seed, steps=400):
    """A random walk of the pieces through fns (the module, or its uncompiled functions),
    beside piece_oracle.Pieces: locate at random arguments, then crossings of finite bounds.
    Returns what the compiled side saw, in order (for the bit comparison)."""
    rng = np.random.default_rng(seed)
    n = model.n
    edges, nedges, intercepts, slopes, rigid = law_arrays(model.laws)
    tu = model.column.rotation_capacity
    silent = model.silent_impacts
    oracle = Pieces(model, silent=True)
    side, k = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    pending, awaiting = np.zeros(n, dtype=np.bool_), np.zeros(n, dtype=np.bool_)
    lo, hi, off = np.empty(n), np.empty(n), np.empty(4 * n)
    seen = []
    kinks = np.concatenate([e[: nedges[i]] for i, e in enumerate(edges)] + [[0.0]])
    x = rng.choice([-1.0, 1.0], n) * rng.choice(kinks, n) * rng.choice([1.0, 0.5, 1.5], n)
    rate = rng.choice([-1.0, 0.0, 1.0], n)
    fns.locate(x, rate, side, k, pending, rigid, edges, nedges)
    oracle.locate(x, rate)
    for _ in range(steps):
        assert (side == oracle.side).all() and (k == oracle.k).all()
        assert (pending == oracle.pending).all() and (awaiting == oracle.awaiting).all()
        fns.bound_rows(side, k, pending, rigid, edges, nedges, tu, 0.9, lo, hi, off)
        want_lo, want_hi = oracle.bounds()
        assert (lo == want_lo).all() and (hi == want_hi).all()
        for i in range(n):
            assert (lo[i], hi[i]) == fns.piece_bounds(i, side, k, pending, rigid, edges, nedges)
            # a row is EVENT_EPS on its bound, BIG + EVENT_EPS for an infinite one
            for row, bound, sign in ((i, lo[i], 1.0), (n + i, hi[i], -1.0)):
                if math.isinf(bound):
                    assert off[row] == BIG + EVENT_EPS
                else:
                    assert sign * bound / tu[i] + off[row] == pytest.approx(EVENT_EPS, abs=1e-15)
        assert (off[2 * n :] == 0.9 + EVENT_EPS).all()
        seen.append((side.copy(), k.copy(), pending.copy(), awaiting.copy(), lo.copy(),
                     hi.copy(), off.copy()))  # fmt: skip
        i = int(rng.integers(n))
        ups = [u for u, b in ((True, hi[i]), (False, lo[i])) if math.isfinite(b)]
        going_up = bool(rng.choice(ups))
        kind = fns.cross(i, going_up, side, k, pending, awaiting, rigid, silent)
        assert KINDS[kind] == oracle.cross(i, going_up)
        if awaiting.any() and rng.random() < 0.5:  # the silent zero crossings
            y = np.concatenate([rng.normal(size=n), np.zeros(n)])
            hits = fns.settle(awaiting, model.arg_map, y, side)
            assert hits == oracle.settle(model.arg_map @ y[:n])
            seen.append(hits)
    return seen


@pytest.mark.parametrize("name", MODELS)
def test_pieces_follow_the_python_bookkeeping_and_plain_gives_the_same(name):
    """locate, cross, settle, piece_bounds and bound_rows agree with piece_oracle.Pieces along a
    random walk through every kind of crossing; the uncompiled functions see the same."""
    model = MODELS[name]()
    seen = _walk(model, compiled, seed=3)
    kinds = {type(s) for s in seen}
    assert int in kinds or not model.silent_impacts.any()  # a silent impact was settled

    class Plain:
        locate, cross = plain(compiled.locate), plain(compiled.cross)
        settle, bound_rows = plain(compiled.settle), plain(compiled.bound_rows)
        piece_bounds = plain(compiled.piece_bounds)

    again = _walk(model, Plain, seed=3)
    assert len(again) == len(seen)
    for a, b in zip(seen, again, strict=True):
        if isinstance(a, int):
            assert a == b
        else:
            assert all(np.array_equal(u, v) for u, v in zip(a, b, strict=True))


@pytest.mark.parametrize("name", MODELS)
def test_law_potential_is_the_laws_potential(name):
    model = MODELS[name]()
    edges, nedges, intercepts, slopes, _ = law_arrays(model.laws)
    for i, law in enumerate(model.laws):
        tu = model.column.rotation_capacity[i]
        for x in np.concatenate([np.linspace(-1.2 * tu, 1.2 * tu, 41), law.edges, -law.edges]):
            want = float(law.potential(x))
            got = compiled.law_potential(i, x, edges, nedges, intercepts, slopes)
            assert got == pytest.approx(want, rel=1e-12, abs=1e-12 * abs(law.intercepts[0] * tu))
            assert plain(compiled.law_potential)(i, x, edges, nedges, intercepts, slopes) == got


def test_shear_ratios_are_the_models_shear_ratio():
    """The shear ratios of an instant are Model.shear_ratios (gam = 1), over gam under
    vertical motion; they raise the peak to their magnitudes."""
    model = MODELS["8 drums, bilinear"]()
    rng = np.random.default_rng(5)
    col = model.column
    out = np.zeros(model.n)
    rx, ry, none = np.zeros(model.n), np.zeros(model.n), np.zeros(0)
    for _ in range(20):
        acc, ag = rng.normal(size=model.n), float(rng.normal())
        want = model.shear_ratios(acc[None, :], np.array([ag]))[0]
        before = out.copy()
        compiled.shear_ratios(ag, 0.0, 1.0, model.centre_map, acc, none, col.masses,
                              col.normal_forces, rx, ry, out)  # fmt: skip
        np.testing.assert_allclose(out, np.maximum(before, np.abs(want)), rtol=1e-12,
                                   atol=1e-15)  # fmt: skip
        np.testing.assert_allclose(np.abs(rx), want, rtol=1e-12, atol=1e-15)
        assert np.all(ry == 0.0)
    under = np.zeros(model.n)
    compiled.shear_ratios(ag, 0.0, 1.25, model.centre_map, acc, none, col.masses,
                          col.normal_forces, rx, ry, under)  # fmt: skip
    np.testing.assert_allclose(under, np.abs(want) / 1.25, rtol=1e-12)
    np.testing.assert_allclose(np.abs(rx), np.abs(want) / 1.25, rtol=1e-12)


def test_rest_levels():
    """The early stop's barrier is the monolith's energy at its collapse ratio at rest, the
    rest rate scales with p and theta_u; a column of drums has neither barrier nor uplift."""
    block = MODELS["rigid block"]()
    uplift, rest_rate, barrier = rest_levels(block)
    tu = block.column.rotation_capacity
    assert uplift == block.uplift_level and uplift > 0.0
    assert barrier == pytest.approx(block.energy(block.collapse_ratio * tu, np.zeros(1))[0])
    assert barrier > 0.0
    assert 0.0 < rest_rate < block.rocking_p * tu[0]
    uplift, _, barrier = rest_levels(MODELS["8 drums, bilinear"]())
    assert uplift is None and math.isnan(barrier)
