"""One source, compiled or not (rbm_cli.base.jit): the uncompiled version of a compiled
function runs the same statements, so it gives the same bits.

The whole-run checks are independent of how the kernel is written: they hold whatever
the algorithm, and fail where numba's semantics and Python's part (an integer that wraps,
a float32, a fused multiply-add, another libm).
"""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from rbm_cli.base.jit import is_compiled, jit, plain
from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.rbm.step import integrate
from rbm_cli.study.simulate import model_from_config

from .paths import CONFIGS


@jit
def _square(x):
    return x * x


@jit
def _sum_of_squares(values):
    total = 0.0
    for v in values:
        total += _square(v)
    return total


def test_plain_calls_plain_callees_and_leaves_the_module_alone():
    """plain() copies a compiled function with its compiled callees replaced by theirs;
    the module's own names stay compiled."""
    if not is_compiled(_sum_of_squares):
        pytest.skip("RBM_JIT=0: nothing is compiled")  # pragma: no cover
    slow = plain(_sum_of_squares)
    assert not is_compiled(slow)
    assert not is_compiled(slow.__globals__["_square"])
    assert is_compiled(globals()["_square"]) and is_compiled(_sum_of_squares)
    values = np.linspace(-1.0, 1.0, 11)
    assert slow(values) == _sum_of_squares(values)
    assert plain(slow) is slow and plain(_sum_of_squares) is slow  # made once


def _solver(cfg, implementation, **kw):
    return dataclasses.replace(cfg.solver, implementation=implementation, **kw)


@pytest.mark.parametrize(
    ("study", "amplitude", "frequency", "method"),
    [
        ("spanos_koh_slender", 0.5, 2.0, "DOP853"),  # a rigid block: rest, uplift, impacts
        ("harmonic_monolithic", 0.5, 2.0, "RK45"),  # an elastic monolith
        pytest.param("harmonic_multidrum", 0.15, 2.0, "DOP853", marks=pytest.mark.slow),  # 8 drums
    ],
)
def test_the_kernel_uncompiled_gives_the_same_bits(study, amplitude, frequency, method):
    """solver.implementation: python runs the step kernel's own source uncompiled: every
    figure of the run and every sample of its history, bit for bit."""
    cfg = load_config(CONFIGS / f"{study}.yaml")
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    motion = dataclasses.replace(motion, t_end=min(motion.t_end, 1.5))  # seconds of Python
    zeros = np.zeros(model.n)
    runs = [
        integrate(model, motion, zeros, zeros, _solver(cfg, impl, method=method), record=True)
        for impl in ("compiled", "python")
    ]
    a, b = (vars(r) for r in runs)
    for key in a:
        x, y = a[key], b[key]
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=key)
        elif key == "samples":
            assert len(x) == len(y)
            for sx, sy in zip(x, y, strict=True):
                for ex, ey in zip(sx, sy, strict=True):
                    np.testing.assert_array_equal(ex, ey)
        elif isinstance(x, float) and x != x:
            assert y != y, key
        else:
            assert x == y, key


SWEEP = """\
name: {name}
column: {column}
interface: {interface}
excitation: {{type: harmonic, duration: 2.0}}
grid: {{amplitudes: [0.15, 0.3, 0.6], frequencies: [1.0, 2.5]}}
"""


@pytest.mark.slow
def test_rbm_jit_0_sweeps_as_the_compiled_code(tmp_path):
    """RBM_JIT=0 runs the whole program uncompiled: a rigid block's and a 2-drum column's
    sweeps give the same domain.csv, byte for byte, as the compiled code's."""
    configs = {
        "rigid": ("{height: 2.0, base_width: 0.5}", "{stiffness: rigid}"),
        "twodrum": (
            "{height: 5.0, base_width: 0.96, top_width: 0.66, drums: 2}",
            "{stiffness: {normal: 5e9}}",
        ),
    }
    for name, (column, interface) in configs.items():
        path = tmp_path / f"{name}.yaml"
        path.write_text(SWEEP.format(name=name, column=column, interface=interface))
        outputs = {}
        for switch in ("1", "0"):
            env = dict(os.environ, RBM_JIT=switch, MPLBACKEND="Agg")
            out = tmp_path / f"out{switch}"
            res = subprocess.run(
                [sys.executable, "-m", "rbm_cli", "sweep", str(path), "-o", str(out),
                 "--jobs", "1", "--quiet"],
                env=env, capture_output=True, text=True, timeout=900,
            )  # fmt: skip
            assert res.returncode == 0, res.stderr
            outputs[switch] = (out / name / "domain.csv").read_bytes()
            meta = json.loads((out / name / "meta.json").read_text())
            assert meta["n_cells"] == 6
        assert outputs["0"] == outputs["1"], name


_LITERALS = """
from rbm_cli.base.jit import jit


@jit
def shifted(x, k):
    return x + k


@jit
def caller(x, k):
    return shifted(x, 0) + shifted(x, k) + shifted((x, -1)[0], 1)


print(caller(1, 2), len(shifted.signatures), [str(s) for s in shifted.signatures])
"""


def test_a_constant_argument_compiles_its_callee_once(tmp_path):
    """A compiled callee called with constants (0, a tuple holding -1) and with a variable
    of the same type is compiled once, for the plain types: numba would compile it for the
    literals first and again for the plain types (the run loop was compiled twice on every
    first use)."""
    (tmp_path / "literals.py").write_text(_LITERALS)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path]),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}  # fmt: skip
    res = subprocess.run([sys.executable, "-c", "import literals"], capture_output=True,
                         text=True, env=env, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr
    value, count, signatures = res.stdout.split(" ", 2)
    assert value == "6" and count == "1", signatures
