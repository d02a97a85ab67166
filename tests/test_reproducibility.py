"""The same answer on any machine.

1. Other machines, proved from this one: the 8-drum CI sub-grid is re-made in
   subprocesses that change what differs between x86-64 machines: numba's
   compile target (NUMBA_CPU_NAME=generic: no AVX, no FMA), OpenBLAS's kernel
   (OPENBLAS_CORETYPE), and glibc's libm variant (GLIBC_TUNABLES without FMA
   and AVX2). Each must pass the regression rule against the stored domain,
   and (rbm_cli.base.detmath) give the same bytes as this process's run: before
   detmath, OPENBLAS_CORETYPE=SkylakeX changed 5 and Sandybridge 2 of 100
   8-drum cells, glibc without FMA 5 (docs/reproducibility.md).
2. The deterministic arithmetic itself: fdlibm's sin and asin within 1 ulp of
   the C library's, the loops equal to BLAS's products to rounding.
3. The regression rule on hand-made domains: it can fail in each way it claims.
4. meta.json's provenance.
"""

from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from numba import njit

from rbm_cli.api import run_sweep
from rbm_cli.base import detmath
from rbm_cli.config.load import load_config
from rbm_cli.study.domain import read_domain
from rbm_cli.study.regression import check, sensitive_bound

from .paths import CONFIGS, RESULTS, ROOT

#: Slow (whole domains re-made, processes killed, contact-engine runs):
#: `pytest -m 'not slow'` leaves this file out.
pytestmark = pytest.mark.slow

CI_CONFIG = CONFIGS / "ci" / "harmonic_multidrum_ci.yaml"
CI_STORED = RESULTS / "harmonic_multidrum_ci" / "domain.csv"


def _cpu_flags() -> set[str]:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("flags"):
                return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return set()


def _variants() -> dict[str, dict[str, str]]:
    """Machines other than this one, as environment changes this CPU can run."""
    flags = _cpu_flags()
    other_blas = "SkylakeX" if "avx512f" in flags else "Haswell" if "fma" in flags else "Core2"
    return {
        # an old x86-64: numba's generic target, OpenBLAS's SSE3 kernel, libm without FMA
        "generic-prescott-nofma": {
            "NUMBA_CPU_NAME": "generic",
            "OPENBLAS_CORETYPE": "Prescott",
            "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA",
            "OPENBLAS_NUM_THREADS": "1",
        },
        # this CPU's numba target with another OpenBLAS kernel (wider vectors)
        f"host-{other_blas.lower()}": {"OPENBLAS_CORETYPE": other_blas},
    }


needs_x86_linux = pytest.mark.skipif(
    platform.machine() not in ("x86_64", "AMD64") or sys.platform != "linux",
    reason="the variants are x86-64 Linux environment settings",
)


@pytest.fixture(scope="module")
def here(tmp_path_factory) -> bytes:
    """The CI band's domain.csv made in this process (this machine's settings)."""
    folder = tmp_path_factory.mktemp("here")
    return (run_sweep(load_config(CI_CONFIG), folder, jobs=1).folder / "domain.csv").read_bytes()


@needs_x86_linux
@pytest.mark.may_skip(reason="the variants are x86-64 settings: another Linux machine skips")
@pytest.mark.parametrize("name", sorted(_variants()))
def test_other_machines_pass_the_regression_rule_with_the_same_bytes(name, tmp_path, here):
    env = dict(os.environ, **_variants()[name])
    if env.get("NUMBA_CPU_NAME") == "generic":  # its own cache: another target's code
        env["NUMBA_CACHE_DIR"] = str(tmp_path / "numba-cache")
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "rbm_cli", "sweep", str(CI_CONFIG), "-o", str(out), "-j", "1",
           "--quiet"]  # fmt: skip
    res = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    folder = out / "harmonic_multidrum_ci"
    fresh = read_domain(folder / "domain.csv")
    result = check(read_domain(CI_STORED), fresh)
    assert result.ok, result.summary()
    assert (folder / "domain.csv").read_bytes() == here
    meta = json.loads((folder / "meta.json").read_text())
    if "NUMBA_CPU_NAME" in _variants()[name]:
        assert meta["provenance"]["numba_target"] == "generic"


# ---------------------------------------------------------------- detmath
@njit
def _sin_many(xs, out):
    for i in range(xs.size):
        out[i] = detmath.sin(xs[i])


@njit
def _asin_many(xs, out):
    for i in range(xs.size):
        out[i] = detmath.asin(xs[i])


def _ulps(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    return np.abs(x - ref) / np.spacing(np.maximum(np.abs(ref), 1e-300))


@pytest.mark.parametrize("half_range", [1.0, 50.0, 1e4, 1.5e6])
def test_sin_is_within_one_ulp_of_the_c_library(half_range):
    xs = np.random.default_rng(3).uniform(-half_range, half_range, 20000)
    xs = np.concatenate([xs, [0.0, -0.0, 1e-30, math.pi / 4, math.pi / 2, math.pi, 1e-9]])
    out = np.empty_like(xs)
    _sin_many(xs, out)
    ref = np.array([math.sin(x) for x in xs])
    assert _ulps(out, ref).max() <= 1.0


def test_sin_edges():
    assert math.isnan(detmath.sin(math.inf)) and math.isnan(detmath.sin(math.nan))
    assert detmath.sin(-0.0) == 0.0 and detmath.sin(1e-300) == 1e-300


def test_asin_is_within_one_ulp_of_the_c_library():
    xs = np.random.default_rng(4).uniform(-1.0, 1.0, 20000)
    xs = np.concatenate([xs, [0.0, 0.5, -0.5, 0.975, 0.9749999046325684, 1.0, -1.0, 1e-12]])
    out = np.empty_like(xs)
    _asin_many(xs, out)
    ref = np.array([math.asin(x) for x in xs])
    assert _ulps(out, ref).max() <= 1.0
    assert math.isnan(detmath.asin(1.0000001))


def test_products_and_inverse_agree_with_blas_to_rounding():
    rng = np.random.default_rng(5)
    a, b, v = rng.normal(size=(9, 9)), rng.normal(size=(9, 4)), rng.normal(size=9)
    np.testing.assert_allclose(detmath.product(a, b), a @ b, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(detmath.product(a, v), a @ v, rtol=1e-13, atol=1e-13)
    assert detmath.product(v, v) == pytest.approx(v @ v, rel=1e-14)
    np.testing.assert_allclose(detmath.inverse(a) @ a, np.eye(9), atol=1e-12)
    with pytest.raises(np.linalg.LinAlgError):
        detmath.inverse(np.ones((3, 3)))


# ---------------------------------------------------------------- the rule
def _domain(collapsed, robust=None):
    amps = [0.1 * (i + 1) for i in range(len(collapsed))]
    df = pd.DataFrame({"amplitude_g": amps, "frequency_hz": 1.0,
                       "status": ["collapsed" if c else "survived" for c in collapsed],
                       "collapsed": collapsed})  # fmt: skip
    if robust is not None:
        df["robust"] = robust
    return df


def test_the_rule_fails_on_a_robust_cell_and_not_on_a_sensitive_one():
    stored = _domain([0, 0, 1, 1], robust=[1, 0, 1, 1])
    assert check(stored, _domain([0, 0, 1, 1])).ok
    sensitive_moved = check(stored, _domain([0, 1, 1, 1]))
    assert sensitive_moved.ok and sensitive_moved.sensitive_differ == 1
    robust_moved = check(stored, _domain([1, 0, 1, 1]))
    assert not robust_moved.ok and robust_moved.robust_differ == 1
    assert "0.1 g at 1 Hz" in robust_moved.summary()


def test_the_rule_fails_on_missing_cells_and_on_a_noisier_model():
    stored = _domain([0, 0, 1, 1, 1], robust=[1, 0, 1, 1, 1])
    assert not check(stored, _domain([0, 0, 1, 1])).ok  # a cell missing
    bound = sensitive_bound(1)
    assert bound == 1 + 3
    noisy = _domain([0, 0, 1, 1, 1], robust=[0, 0, 0, 0, 0])
    assert check(stored, noisy).fresh_sensitive == 5 > bound and not check(stored, noisy).ok
    calm = _domain([0, 0, 1, 1, 1], robust=[1, 0, 0, 1, 1])
    assert check(stored, calm).ok


def test_the_rule_needs_a_stored_robustness_record():
    from rbm_cli.base.errors import RbmError

    with pytest.raises(RbmError, match="--ensemble 16"):
        check(_domain([0, 1]), _domain([0, 1]))


# ---------------------------------------------------------------- provenance
def test_meta_records_what_a_result_depends_on(tmp_path):
    import llvmlite
    import numba
    import scipy

    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    import dataclasses

    from rbm_cli.config.types import GridConfig

    cfg = dataclasses.replace(cfg, grid=GridConfig(amplitudes_g=(0.3,), frequencies_hz=(1.0,)))
    meta = json.loads((run_sweep(cfg, tmp_path, jobs=1).folder / "meta.json").read_text())
    prov = meta["provenance"]
    assert prov["numpy"] == np.__version__ and prov["scipy"] == scipy.__version__
    assert prov["numba"] == numba.__version__ and prov["llvmlite"] == llvmlite.__version__
    assert prov["python"] == platform.python_version()
    assert prov["rbm"] and prov["cpu_model"] and prov["numba_target"]
    assert "robust" in prov["robustness_rule"]
    if (ROOT / ".git").exists():
        assert prov["git_commit"] and len(prov["git_commit"].split("-")[0]) == 40


# ---------------------------------------------------------------- the documented figures
def test_docs_state_each_studys_sensitive_cells():
    """docs/reproducibility.md's table of sensitive cells is the stored domains' (and lists
    every regressed study): re-making a study without updating the page fails here."""
    from .test_regression import STUDIES

    text = (ROOT / "docs" / "reproducibility.md").read_text()
    section = text.split("## 7. Every stored study", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip(" `") for c in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[1].isdigit():
            solver, both = (int(c) for c in cells[4].split("/"))
            rows[cells[0]] = (*(int(c) for c in cells[1:4]), solver, both)
    assert set(rows) == set(STUDIES)
    for name, (n_cells, members, sensitive, solver, both) in rows.items():
        df = read_domain(RESULTS / name / "domain.csv")
        meta = json.loads((RESULTS / name / "meta.json").read_text())
        why = df["sensitive_to"].value_counts()
        assert (len(df), meta["ensemble"]["members"], int((df["robust"] != 1).sum())) == (
            n_cells, members, sensitive), name  # fmt: skip
        assert (why.get("solver", 0), why.get("both", 0)) == (solver, both), name


def test_cli_compare_applies_the_rule_to_a_stored_ensemble(tmp_path):
    """rbm compare STORED FRESH: exit 0 when only sensitive cells differ, 1 when a
    robust one does."""
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    stored = _domain([0, 0, 1, 1], robust=[1, 0, 1, 1])
    stored.to_csv(tmp_path / "a.csv", index=False)
    _domain([0, 1, 1, 1]).to_csv(tmp_path / "b.csv", index=False)
    _domain([0, 0, 0, 1]).to_csv(tmp_path / "c.csv", index=False)
    ok = CliRunner().invoke(cli, ["compare", str(tmp_path / "a.csv"), str(tmp_path / "b.csv")])
    assert ok.exit_code == 0 and "sensitive cells (stored): 1, 1 differ" in ok.output
    bad = CliRunner().invoke(cli, ["compare", str(tmp_path / "a.csv"), str(tmp_path / "c.csv")])
    assert bad.exit_code == 1 and "robust cells: 1 of 3 differ" in bad.output
