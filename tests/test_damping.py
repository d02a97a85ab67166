"""Viscous damping of the joints' elastic branch (interface.damping: zeta).

Checked against what holds independently of the code:
- a free vibration of a 2-drum elastic column started in its first mode (the mode from
  scipy's generalized eigenproblem, inside the elastic range) decays with the logarithmic
  decrement of zeta: successive peaks of the top displacement in the ratio
  exp(2 pi zeta / sqrt(1 - zeta^2)) (stiffness-proportional damping keeps the modes, so the
  first mode stays alone and its damping ratio is zeta), in every method that takes damping;
- the energy balance closes: start + the ground's work - damping - impacts = end, each
  term computed on its own (the work and the damping by quadrature over the run, the
  impacts as the energy jump at each one, start and end from the state);
- rigid rocking is not damped: a lifted joint's excursion is the undamped one, to the bit,
  until the joint closes onto its elastic branch;
- zeta 0 is the undamped column (the same config hash, the same run);
- what cannot be damped is refused in one line.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eig

from rbm_cli.api import info as rbm_info
from rbm_cli.api import load_config, run, run_sweep
from rbm_cli.api.configs import with_values
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.models.methods import resolve_method
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.study.domain import read_domain

from .paths import CONFIGS, RESULTS

TWO_DRUMS = {"height": 2.0, "base_width": 0.5, "drums": 2}
SOFT = {"normal": 5e8}  # first elastic frequency 5.7 Hz


def _config(zeta, method="DOP853", implementation="python", **excitation):
    return {
        "name": "two",
        "column": TWO_DRUMS,
        "interface": {"stiffness": SOFT, "damping": zeta},
        "excitation": excitation or {"type": "free", "duration": 1.0,
                                     "initial": {"rotations": [1e-9, 1e-9]}},
        "solver": {"method": method, "implementation": implementation, "rtol": 1e-10,
                   "atol": 1e-12},
    }  # fmt: skip


def _first_mode(cfg: dict, which: int = 0) -> tuple[np.ndarray, float]:
    """The first (or which-th) elastic mode's drum rotations [rad] at half the elastic limit
    of the joint nearest to it, and its frequency [Hz], from scipy's eigenproblem
    K v = w^2 M v."""
    model = model_from_config(load_config(cfg))
    slopes = np.array([law.slopes[0] for law in model.laws])
    w2, vecs = eig(model.stiffness(slopes), model.mass)
    first = int(np.argsort(w2.real)[which])
    phi = vecs[:, first].real
    elastic_end = model.column.moment_capacity / model.column.stiffness  # xi = 1
    phi *= 0.5 * np.min(elastic_end / np.abs(model.arg_map @ phi))
    return phi, math.sqrt(w2[first].real) / (2 * math.pi)


def _peaks(u: np.ndarray) -> np.ndarray:
    """Positive local maxima of a sampled signal."""
    i = np.flatnonzero((u[1:-1] > u[:-2]) & (u[1:-1] >= u[2:]) & (u[1:-1] > 0)) + 1
    return u[i]


@pytest.mark.parametrize(
    "method, implementation",
    [("DOP853", "compiled"), ("DOP853", "python"), ("RK45", "compiled"), ("RK23", "compiled")],
)
@pytest.mark.parametrize("zeta", [0.05, 0.2])
def test_first_mode_decays_with_the_logarithmic_decrement_of_zeta(zeta, method, implementation):
    cfg = _config(zeta, method, implementation)
    phi, f1 = _first_mode(cfg)
    cfg["excitation"] = {"type": "free", "duration": 6.0 / f1,
                         "initial": {"rotations": [float(v) for v in phi]}}  # fmt: skip
    if method == "RK23":
        cfg["solver"]["rtol"] = 1e-8
    cell = run(cfg, amplitude_g=0.0, frequency_hz=1.0, record=True, output_dt=1e-3 / f1)
    assert cell.status == "survived" and cell.result["n_uplifts"] == 0  # elastic throughout
    h = cell.history
    peaks = _peaks(h["u3_m"].to_numpy() - h["u1_m"].to_numpy())
    assert len(peaks) >= 5
    delta = np.log(peaks[:-1] / peaks[1:])
    measured = delta / np.sqrt(4 * math.pi**2 + delta**2)
    assert np.all(np.abs(measured - zeta) < zeta / 10), measured
    # closer than the tenth asked of it: one mode alone, integrated at rtol 1e-10 (1e-8)
    assert np.all(np.abs(measured - zeta) < 1e-3 * zeta), measured


def test_the_second_mode_has_the_ratio_rbm_info_states():
    """Stiffness-proportional damping gives mode k the ratio zeta w_k / w_1: the second mode,
    started alone, decays with that logarithmic decrement, and `rbm info` says so."""
    zeta = 0.02
    cfg = _config(zeta, implementation="compiled")
    phi, f2 = _first_mode(cfg, which=1)
    _, f1 = _first_mode(cfg)
    cfg["excitation"] = {"type": "free", "duration": 5.0 / f2,
                         "initial": {"rotations": [float(v) for v in phi]}}  # fmt: skip
    cell = run(cfg, amplitude_g=0.0, frequency_hz=1.0, record=True, output_dt=1e-3 / f2)
    h = cell.history
    peaks = _peaks(h["u2_m"].to_numpy() - h["u1_m"].to_numpy())
    delta = np.log(peaks[:-1] / peaks[1:])
    measured = delta / np.sqrt(4 * math.pi**2 + delta**2)
    assert np.all(np.abs(measured - zeta * f2 / f1) < 1e-3 * zeta * f2 / f1), measured
    stated = rbm_info(load_config(cfg))["damping_ratios"]
    assert stated[1] == pytest.approx(zeta * f2 / f1, rel=1e-9)
    assert stated[0] == pytest.approx(zeta, rel=1e-12)


@pytest.mark.parametrize("zeta, restitution", [(0.05, 0.9), (0.0, 0.9), (0.1, 1.0)])
def test_the_energy_balance_closes_with_uplift_impacts_and_damping(zeta, restitution):
    cfg = _config(zeta, type="harmonic", duration=3.0)
    cfg["interface"]["restitution"] = restitution
    cfg["solver"] = {"method": "DOP853", "implementation": "compiled"}  # default tolerances
    cell = run(cfg, amplitude_g=0.3, frequency_hz=2.0, record=True)
    r = cell.result
    assert r["n_uplifts"] > 5  # the joints lift and close: every term is at work
    e = r["energy"]
    assert e["ground_work_J"] > 0
    assert (e["damping_J"] > 0) == (zeta > 0) and e["damping_J"] >= 0
    assert (e["impacts_J"] > 0) == (restitution < 1 and r["n_impacts"] > 0)
    kept = e["final_J"] - e["initial_J"]
    balance = kept - (e["ground_work_J"] - e["damping_J"] - e["impacts_J"])
    assert balance == pytest.approx(e["residual_J"], abs=1e-12 * e["ground_work_J"])
    # the stated tolerance (docs): 1e-8 of the ground's work at the default tolerances
    assert abs(balance) <= 1e-8 * e["ground_work_J"], e


def test_free_decay_takes_the_energy_the_damping_took():
    """Free motion: the energy at the end is the start less what damping took, and that
    is the closed form's share, 1 - exp(-2 zeta w1 t) of the start at whole periods."""
    zeta = 0.05
    cfg = _config(zeta)
    phi, f1 = _first_mode(cfg)
    periods = 5
    cfg["excitation"] = {"type": "free", "duration": periods / (f1 * math.sqrt(1 - zeta**2)),
                         "initial": {"rotations": [float(v) for v in phi]}}  # fmt: skip
    e = run(cfg, amplitude_g=0.0, frequency_hz=1.0, record=True).result["energy"]
    assert e["ground_work_J"] == 0.0 and e["impacts_J"] == 0.0
    assert e["initial_J"] - e["final_J"] == pytest.approx(e["damping_J"], rel=1e-9)
    # at rest in position after whole damped periods: E(t) / E(0) = exp(-2 zeta w1 t)
    t = periods / (f1 * math.sqrt(1 - zeta**2))
    assert e["final_J"] / e["initial_J"] == pytest.approx(
        math.exp(-2 * zeta * 2 * math.pi * f1 * t), rel=1e-6
    )


def test_a_lifted_joint_rocks_undamped_until_it_closes():
    """A monolith on a soft joint, released beyond its elastic limit: until the joint
    returns to its elastic branch the damped run is the undamped run, to the bit."""
    base = {"name": "one", "column": {"height": 2.0, "base_width": 0.5},
            "interface": {"stiffness": {"normal": 5e8}},
            "excitation": {"type": "free", "duration": 0.5, "initial": {"rotations": [0.05]}},
            "solver": {"method": "DOP853", "implementation": "python"}}  # fmt: skip
    damped = {**base, "interface": {**base["interface"], "damping": 0.1}}
    a = run(base, amplitude_g=0.0, frequency_hz=1.0, record=True, output_dt=1e-3).history
    b = run(damped, amplitude_g=0.0, frequency_hz=1.0, record=True, output_dt=1e-3).history
    model = model_from_config(load_config(base))
    elastic_end = float(model.column.moment_capacity[0] / model.column.stiffness[0])
    theta = a["theta1_rad"].to_numpy()
    closes = int(np.argmax(np.abs(theta) <= elastic_end))
    assert closes > 10  # it rocks a while on its edge first
    np.testing.assert_array_equal(a["theta1_rad"][:closes], b["theta1_rad"][:closes])
    assert not np.array_equal(a["theta1_rad"], b["theta1_rad"])  # then the damping acts


def test_zero_damping_is_the_undamped_column():
    undamped = _config(0.05)
    del undamped["interface"]["damping"]
    zero = _config(0.0)
    assert load_config(zero).resolved() == load_config(undamped).resolved()
    assert load_config(zero).resolved()["interface"]["damping"] == 0.0


def test_auto_runs_a_damped_column_with_a_method_that_damps():
    cfg = load_config(_config(0.05, method="auto", implementation="compiled"))
    assert resolve_method(cfg) == "DOP853"


@pytest.mark.parametrize(
    "interface, model, message",
    [
        ({"stiffness": SOFT, "damping": 1.0}, "rbm", "damping must be a number in [0, 1)"),
        ({"stiffness": SOFT, "damping": -0.01}, "rbm", "interface.damping must be a number"),
        ({"stiffness": SOFT, "damping": "5%"}, "rbm", "interface.damping must be a number"),
        ({"damping": 0.05}, "housner", "interface.damping applies only to models rbm and rbm-3d"),
        (
            {"damping": 0.05},
            "housner-linear",
            "interface.damping applies only to models rbm and rbm-3d",
        ),
        ({"damping": 0.05}, "rbm", "a rigid interface does not have"),
    ],
)
def test_what_cannot_be_damped_is_refused_in_one_line(interface, model, message):
    cfg = {"name": "bad", "model": model, "column": {"height": 2.0, "base_width": 0.5},
           "interface": interface}  # fmt: skip
    with pytest.raises(ConfigError, match=message.replace("[", r"\[").replace(")", r"\)")) as exc:
        load_config(cfg)
    assert "\n" not in str(exc.value)


def test_the_exact_method_refuses_damping_in_one_line():
    cfg = _config(0.05, method="exact", implementation="compiled", type="harmonic", duration=1.0)
    with pytest.raises(RbmError, match="solver.method exact does not take interface.damping"):
        run(cfg, amplitude_g=0.1, frequency_hz=2.0)


@pytest.mark.slow
def test_the_stored_damped_study_is_reproduced(tmp_path):
    """The stored damped 8-drum study (results/harmonic_multidrum_damped, an ensemble of 16)
    on a sub-grid of 6 cells across its boundary: the same outcome on its robust cells, the
    same peak to the digit on every cell (one member, the stored member 0)."""
    name = "harmonic_multidrum_damped"
    stored = read_domain(RESULTS / name / "domain.csv")
    cfg = load_config(CONFIGS / f"{name}.yaml")
    assert cfg.interface.damping == 0.05
    sub = with_values(cfg, {"grid.amplitudes": [0.35, 0.55, 0.7], "grid.frequencies": [1.5, 2.0]})
    fresh = read_domain(run_sweep(sub, tmp_path, jobs=2).folder / "domain.csv")
    merged = fresh.merge(stored, on=["amplitude_g", "frequency_hz"], suffixes=("", "_stored"))
    assert len(merged) == 6 and merged["collapsed"].nunique() == 2  # both sides of it
    robust = merged["robust"] == 1
    assert robust.sum() >= 4
    assert (merged.loc[robust, "collapsed"] == merged.loc[robust, "collapsed_stored"]).all()
    assert (merged["max_rotation_ratio"] == merged["max_rotation_ratio_stored"]).all()


def test_the_domain_figure_states_the_damping():
    from rbm_cli.report.domain_figure import column_note

    damped = column_note(load_config(CONFIGS / "harmonic_multidrum_damped.yaml"))
    assert "damping zeta = 0.05" in damped and "e = 1" in damped
    assert "damping" not in column_note(load_config(CONFIGS / "harmonic_multidrum.yaml"))


def test_the_damping_coefficients_do_not_depend_on_the_last_bits_of_the_eigenvalues(monkeypatch):
    """The joints' damping coefficients come from the first elastic frequency, which LAPACK
    computes; its last bits follow the processor's kernels. A frequency a few ulp away (as
    another machine may give) must give the same coefficients, to the bit: the stored damped
    study is reproduced on every machine."""
    from rbm_cli.structures.equations import Model

    cfg = load_config(CONFIGS / "harmonic_multidrum_damped.yaml")
    reference = model_from_config(cfg).joint_damping
    assert reference.any()
    exact = Model.elastic_frequencies_hz
    for ulps in (-3, -1, 1, 3):

        def shifted(self, ulps=ulps):
            freqs = exact(self)
            f = freqs[0]
            for _ in range(abs(ulps)):
                f = float(np.nextafter(f, math.inf if ulps > 0 else -math.inf))
            return [f, *freqs[1:]]

        monkeypatch.setattr(Model, "elastic_frequencies_hz", shifted)
        again = model_from_config(cfg).joint_damping
        assert again.tobytes() == reference.tobytes(), ulps
    # the coefficients still give the first mode the ratio asked for (1e-10 relative)
    monkeypatch.setattr(Model, "elastic_frequencies_hz", exact)
    model = model_from_config(cfg)
    omega_1 = 2.0 * math.pi * exact(model)[0]
    beta = reference / np.asarray(model.column.stiffness, dtype=float)
    assert np.allclose(beta * omega_1 / 2.0, cfg.interface.damping, rtol=1e-10, atol=0.0)
