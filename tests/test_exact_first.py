"""`solver.method: exact-first` (rbm_cli.models.rbm.exact_first) on an RBM column whose
joints are all elastic, over whole domains (a record and a harmonic grid) against the step
kernel (DOP853) run alone:

- a cell where a joint opens is the step kernel's run, bit for bit: every figure of its row;
- a cell where none opens is the exact integrator's: the same outcome, no uplift in the
  step kernel's run either, and peaks within 1e-8 relative of the step kernel at rtol 1e-12;
- both kinds are in each domain (the choice is made cell by cell), and the row says which
  method ran.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.inputs.records import write_csv
from rbm_cli.models.methods import resolve_method
from rbm_cli.models.registry import make_runner
from rbm_cli.study.simulate import simulate

COLUMN = {"height": 3.0, "base_width": 0.6, "top_width": 0.45, "drums": 3}
INTERFACE = {"stiffness": {"normal": 5e9}}
AMPLITUDES = (0.02, 0.05, 0.1, 0.15, 0.2, 0.3)  # g


def _record(folder):
    """A 4 s record, a windowed sum of three sines (1.3, 3.1, 7.4 Hz), sampled at 0.01 s."""
    t = np.arange(0.0, 4.0 + 1e-9, 0.01)
    a = np.sin(np.pi * t / 4.0) ** 2 * (np.sin(2 * np.pi * 1.3 * t)
                                        + 0.6 * np.sin(2 * np.pi * 3.1 * t + 0.4)
                                        + 0.3 * np.sin(2 * np.pi * 7.4 * t + 1.1))  # fmt: skip
    return write_csv(folder / "r.csv", (t, a), units="g")


def _configs(excitation):
    base = {"name": "ef", "column": COLUMN, "interface": INTERFACE, "excitation": excitation}
    first = parse_config({**base, "solver": {"method": "exact-first"}})
    step = parse_config({**base, "solver": {"method": "DOP853"}})
    tight = parse_config({**base, "solver": {"method": "DOP853", "rtol": 1e-12}})
    return first, step, tight


def _domain(first, step, tight, cells):
    """(exact-first row, DOP853 row, DOP853 rtol 1e-12 row) of every cell (amplitude,
    frequency)."""
    configs = (first, step, tight)
    runners = [make_runner(c) for c in configs]
    return [tuple(simulate(c, a, f, runner=r) for c, r in zip(configs, runners, strict=True))
            for a, f in cells]  # fmt: skip


def _check(rows):
    kinds = set()
    for first, alone, tight in rows:
        kinds.add(first.method)
        if first.method == "DOP853":
            assert first.row() == alone.row()  # the step kernel's run, bit for bit
            assert alone.n_uplifts > 0
        else:
            assert first.method == "exact"
            assert first.status == alone.status == tight.status == "survived"
            assert first.n_uplifts == alone.n_uplifts == tight.n_uplifts == 0
            assert first.max_rotation_ratio == pytest.approx(tight.max_rotation_ratio, rel=1e-8)
            assert first.max_top_displacement_m == pytest.approx(
                tight.max_top_displacement_m, rel=1e-8
            )
    assert kinds == {"exact", "DOP853"}  # the domain holds both kinds of cell


def test_a_record_domain_is_the_step_kernels_where_a_joint_opens(tmp_path):
    path = _record(tmp_path)
    excitation = {"type": "record", "file": str(path), "scale": "pga", "free_time": 1.0}
    first, step, tight = _configs(excitation)
    _check(_domain(first, step, tight, [(a, None) for a in AMPLITUDES]))


def test_a_harmonic_domain_is_the_step_kernels_where_a_joint_opens():
    first, step, tight = _configs({"type": "harmonic", "duration": 3.0})
    _check(_domain(first, step, tight, [(a, f) for a in AMPLITUDES for f in (2.0, 6.0)]))


def test_where_exact_first_applies():
    """It takes elastic RBM columns under what the exact integrator takes (auto keeps
    DOP853 there); on a rigid column, damped joints, the absolute formulation or a Ricker
    pulse it is refused in one line."""
    harmonic = {"type": "harmonic", "duration": 1.0}
    elastic = {"name": "x", "column": COLUMN, "interface": INTERFACE, "excitation": harmonic}
    assert resolve_method(parse_config(elastic)) == "DOP853"
    asked = parse_config({**elastic, "solver": {"method": "exact-first"}})
    assert resolve_method(asked) == "exact-first"
    others = {
        "rigid": {**elastic, "column": {**COLUMN, "drums": 1}, "interface": {"stiffness": "rigid"}},
        "damped": {**elastic, "interface": {**INTERFACE, "damping": 0.02}},
        "absolute": {**elastic, "interface": {**INTERFACE, "formulation": "absolute"}},
        "ricker": {**elastic, "excitation": {"type": "ricker"}},
    }
    for what, written in others.items():
        cfg = parse_config(written)
        assert resolve_method(cfg) != "exact-first", what
        solver = dataclasses.replace(cfg.solver, method="exact-first")
        asked = dataclasses.replace(cfg, solver=solver)
        with pytest.raises(RbmError, match="exact-first") as err:
            make_runner(asked)
        assert "\n" not in str(err.value)
