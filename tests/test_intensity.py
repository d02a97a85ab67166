"""Intensity measures of records (rbm_cli.inputs.intensity) and a record cell's row.

Expected values are closed forms of the sampled signals (a cosine's PGV A / omega, its
Arias intensity pi A^2 T / (4 g) over whole cycles, a constant's Husid line, the steady
resonant response A / (2 zeta)), a Newmark integration written here, eqsig where it is
installed, and the same signal sampled more densely: never the code's own output.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs import intensity as im
from rbm_cli.structures.column import build_column
from rbm_cli.study.cells import add_point, domain_fields
from rbm_cli.study.intensities import MEASURES, column_period, measure_fields, sa_field
from rbm_cli.study.sweep import config_hash

from .paths import CONFIGS

RECORD = CONFIGS / "records" / "synthetic" / "rdk_01.AT2"


def _cosine(amplitude=2.0, period=0.5, cycles=20, dt=1e-4):
    t = np.arange(0.0, cycles * period + 0.5 * dt, dt)
    return t, amplitude * np.cos(2.0 * math.pi * t / period)


def test_cosine_closed_forms():
    A, T, cycles = 2.0, 0.5, 20
    t, a = _cosine(A, T, cycles)
    w = 2.0 * math.pi / T
    m = im.record_measures(t, a)
    length = cycles * T
    assert m.pga == pytest.approx(A, rel=1e-12)
    assert m.pgv == pytest.approx(A / w, rel=1e-6)  # v = A sin(w t) / w
    assert m.pgd == pytest.approx(2.0 * A / w**2, rel=1e-6)  # u = A (1 - cos w t) / w^2
    assert m.arias == pytest.approx(math.pi * A * A * length / (4.0 * G), rel=1e-6)
    assert m.cav == pytest.approx(2.0 * A * length / math.pi, rel=1e-6)  # mean |cos| = 2 / pi


def test_pgv_counts_the_peak_between_samples():
    """A triangle sampled at 3 points: the velocity peaks where a crosses 0, between them."""
    t = np.array([0.0, 1.0, 2.0])
    a = np.array([1.0, -1.0, -1.0])
    # v(t) = t - t^2 on [0, 1]: peak 1/4 at t = 1/2; then v falls to -1 at t = 2
    assert im.peak_velocity(t, a) == pytest.approx(1.0)
    t2, a2 = np.array([0.0, 1.0]), np.array([1.0, -1.0])
    assert im.peak_velocity(t2, a2) == pytest.approx(0.25)


def test_significant_duration_of_a_constant():
    t = np.linspace(0.0, 10.0, 101)
    assert im.significant_duration(t, np.full(t.size, 3.0)) == pytest.approx(9.0, rel=1e-12)
    assert math.isnan(im.significant_duration(t, np.zeros(t.size)))


def test_sa_at_resonance_is_the_steady_amplitude():
    """Sa of a harmonic at the oscillator's period, long enough that the transient has
    decayed by exp(-zeta w t) < 1e-8: A / (2 zeta)."""
    A, T = 0.7, 1.0
    t = np.arange(0.0, 60.0, 0.005)
    a = A * np.sin(2.0 * math.pi * t / T)
    assert im.spectral_acceleration(t, a, T, 0.05) == pytest.approx(A / (2 * 0.05), rel=1e-3)


def _newmark_sa(dt, a, period, zeta):
    """Sa by Newmark's average acceleration on a uniform step (written here)."""
    w = 2.0 * math.pi / period
    k, c = w * w, 2.0 * zeta * w
    khat = k + 2.0 * c / dt + 4.0 / dt**2
    u = v = 0.0
    acc = -a[0]
    peak = 0.0
    for p in -a[1:]:
        rhs = p + (4.0 / dt**2 * u + 4.0 / dt * v + acc) + c * (2.0 / dt * u + v)
        u1 = rhs / khat
        v1 = 2.0 / dt * (u1 - u) - v
        acc = 4.0 / dt**2 * (u1 - u) - 4.0 / dt * v - acc
        u, v = u1, v1
        peak = max(peak, abs(u))
    return w * w * peak


@pytest.mark.parametrize("period", [0.2, 0.7, 2.0])
def test_sa_agrees_with_newmark_on_a_fine_step(period):
    rng = np.random.default_rng(3)
    dt = 0.002
    t = np.arange(0.0, 8.0, dt)
    a = np.convolve(rng.normal(size=t.size), np.ones(25) / 25, mode="same")
    a[-1] = 0.0
    ours = im.spectral_acceleration(t, a, period)
    newmark = _newmark_sa(dt, np.concatenate([a, np.zeros(int(period / dt) + 2)]), period, 0.05)
    assert ours == pytest.approx(newmark, rel=2e-3)


def test_sa_agrees_with_eqsig():
    """eqsig (the field's signal library, a test dependency) on a uniform step."""
    import eqsig

    rng = np.random.default_rng(5)
    dt = 0.001
    t = np.arange(0.0, 6.0, dt)
    a = np.convolve(rng.normal(size=t.size), np.ones(40) / 40, mode="same")
    periods = np.array([0.3, 1.0])
    sig = eqsig.AccSignal(np.concatenate([a, np.zeros(2000)]), dt)
    sig.generate_response_spectrum(response_times=periods, xi=0.05)
    ours = [im.spectral_acceleration(t, a, p) for p in periods]
    np.testing.assert_allclose(ours, sig.s_a, rtol=2e-3)


def test_uneven_steps_are_exact():
    """The same piecewise-linear signal on its own uneven samples and on a dense uniform
    grid (its values interpolated): every measure agrees."""
    rng = np.random.default_rng(1)
    t = np.sort(np.concatenate([[0.0], rng.uniform(0.0, 10.0, 800), [10.0]]))
    a = rng.normal(size=t.size)
    dense = np.unique(np.concatenate([t, np.linspace(0.0, 10.0, 100_001)]))
    a_dense = np.interp(dense, t, a)
    m1 = im.record_measures(t, a, (0.3, 1.5))
    m2 = im.record_measures(dense, a_dense, (0.3, 1.5))
    for name in ("pga", "pgv", "pgd", "arias", "cav", "d5_95"):
        assert getattr(m1, name) == pytest.approx(getattr(m2, name), rel=1e-9), name
    for p in (0.3, 1.5):
        assert m1.sa[p] == pytest.approx(m2.sa[p], rel=1e-6)


def test_scaled_measures_are_those_of_the_scaled_record():
    """Every registry entry's scaling rule gives the measure of the record times c,
    computed on that record."""
    t, a = _cosine(1.0, 0.4, 5, 1e-3)
    a = a * np.exp(-t)
    c = -2.5
    for measure in MEASURES:
        period = None if measure.period is None else 0.25
        direct = measure.compute(t, c * a, period)
        scaled = measure.scaled(measure.compute(t, a, period), c)
        assert scaled == pytest.approx(direct, rel=1e-9), measure.column


# --------------------------------------------------------------------------- config, rows


def _config(**excitation):
    return parse_config(
        {
            "name": "im",
            "column": {"height": 2.0, "base_width": 0.5, "drums": 1},
            "interface": {"stiffness": {"rotational": 4e6}},
            "excitation": {"type": "record", "file": str(RECORD), **excitation},
            "grid": {"amplitudes": [0.2, 0.4]},
        }
    )


def test_first_elastic_period_of_a_monolith():
    """One drum on an elastic interface: (I_G + m h^2 / 4) theta'' + K_M theta = 0."""
    cfg = _config()
    col = build_column(cfg.column, cfg.interface)
    m, h, i_g = col.masses[0], col.heights[0], col.inertias[0]
    expected = 2.0 * math.pi * math.sqrt((i_g + m * h * h / 4.0) / 4e6)
    assert column_period(cfg) == pytest.approx(expected, rel=1e-12)
    rigid = dataclasses.replace(cfg, model="housner")
    assert column_period(rigid) is None


def test_record_row_has_the_measures_scaled():
    cfg = _config(im_periods=[0.5, 1.25])
    assert sa_field(1.25) == "sa_1p25s_g" and sa_field(2.0) == "sa_2s_g"
    fields = domain_fields(cfg, ("status",))
    assert {"pga_g", "arias_m_s", "sa_t1_g", "sa_0p5s_g", "sa_1p25s_g"} <= set(fields)
    rows = [add_point({"amplitude_g": x}, cfg, (x, None, ())) for x in (0.2, 0.4)]
    assert rows[0]["pga_g"] == pytest.approx(0.2, rel=1e-12)
    assert rows[1]["arias_m_s"] == pytest.approx(4.0 * rows[0]["arias_m_s"], rel=1e-12)
    assert rows[1]["sa_0p5s_g"] == pytest.approx(2.0 * rows[0]["sa_0p5s_g"], rel=1e-12)
    assert rows[1]["d5_95_s"] == rows[0]["d5_95_s"]
    tan_alpha = math.tan(rows[0]["alpha_rad"])
    assert rows[0]["pga_over_g_tan_alpha"] == pytest.approx(0.2 / tan_alpha, rel=1e-12)
    assert rows[0]["pgv_p_over_g_tan_alpha"] == pytest.approx(
        rows[0]["pgv_m_s"] * rows[0]["p_rad_s"] / (G * tan_alpha), rel=1e-12
    )


def test_a_processed_record_is_measured_as_processed():
    """With excitation.processing the rows measure the record the run sees: the processed
    samples (rbm_cli.inputs.records.process of the file's samples), scaled to the cell."""
    from rbm_cli.inputs.records import process, read_record

    cfg = _config(processing={"baseline": "quadratic"})
    raw = _config()
    rec = read_record(RECORD, "g")
    t, a = np.asarray(rec.t, float), np.asarray(rec.acceleration, float)
    direct = im.record_measures(t, np.asarray(process(t, a, cfg.excitation.processing)), ())
    row = add_point({"amplitude_g": 0.3}, cfg, (0.3, None, ()))
    row_raw = add_point({"amplitude_g": 0.3}, raw, (0.3, None, ()))
    factor = 0.3 * G / direct.pga
    assert row["pga_g"] == pytest.approx(0.3, rel=1e-12)
    assert row["pgd_m"] == pytest.approx(direct.pgd * factor, rel=1e-9)
    assert row["pgv_m_s"] == pytest.approx(direct.pgv * factor, rel=1e-9)
    assert abs(row["pgd_m"] - row_raw["pgd_m"]) > 1e-3 * row_raw["pgd_m"]


def test_harmonic_rows_have_no_measures():
    cfg = parse_config({"name": "im", "column": {"height": 2.0, "base_width": 0.5},
                        "grid": {"amplitudes": [0.2], "frequencies": [1.0]}})  # fmt: skip
    assert measure_fields(cfg) == ()
    row = add_point({"amplitude_g": 0.2}, cfg, (0.2, 1.0, ()))
    assert "pga_g" not in row


def test_im_periods_do_not_change_the_hash_unless_given():
    assert config_hash(_config()) == config_hash(_config(im_periods=[]))
    assert config_hash(_config()) != config_hash(_config(im_periods=[0.5]))


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ([0.0], "excitation.im_periods"),
        ([0.5, 30.0], "excitation.im_periods[1] must be in [0.01, 20]"),
        ([0.5, 0.5], "each period once"),
        ("0.5", "must be a list"),
        (list(np.linspace(0.1, 2, 21)), "at most 20"),
    ],
)
def test_bad_im_periods(value, words):
    with pytest.raises(ConfigError, match=None) as err:
        _config(im_periods=value)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_im_periods_only_for_records():
    with pytest.raises(ConfigError, match="excitation.im_periods applies only to type record"):
        parse_config({"name": "im", "column": {"height": 2.0, "base_width": 0.5},
                      "excitation": {"type": "harmonic", "im_periods": [0.5]},
                      "grid": {"amplitudes": [0.2], "frequencies": [1.0]}})  # fmt: skip
