"""Processed records (``excitation.processing``): baseline correction and band-pass.

Expected values come from closed forms and second computations, not from the code:

- a polynomial drift added to the acceleration moves the displacement by its closed-form
  double integral (c0 t^2 / 2 + c1 t^3 / 6 + c2 t^4 / 12), and the baseline of its degree
  removes it: the corrected record's displacement is the clean record's, near zero at the
  end; a pure polynomial of that degree is removed to round-off; the fit's coefficients
  match a least-squares fit made here of the analytic displacements of the powers of time;
- a sine through the band-pass keeps the amplitude the Butterworth gain gives, a side
  1 / (1 + (f / f_c)^(2n)) (with scipy's prewarped frequencies, tan(pi f / fs)), squared by
  the forward and backward pass, and its phase; one outside the band is removed;
- with ``scale: pga`` the scaled ground motion's peak is the amplitude (the processed
  record's PGA), not the raw record's; the vertical record is processed the same way;
- bad keys, orders and frequencies are one-line ConfigErrors naming the key;
- ``rbm run`` of a processed record runs with every solver.method that takes records and
  agrees across them; its history.csv holds the processed ground (no drift of metres).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import cumulative_trapezoid

from rbm_cli.base.errors import ConfigError
from rbm_cli.cli.main import cli
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import METHODS, G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.records import (
    band_pass,
    baseline_fit,
    displacement_at_samples,
    process,
    read_record,
    remove_baseline,
    write_at2,
    write_csv,
)
from rbm_cli.study.sweep import config_hash

from .paths import CONFIGS

#: A clean synthetic record (30 s at 0.01 s) whose displacement returns near 0.
CLEAN = CONFIGS / "records" / "synthetic" / "rdk_01.AT2"
#: The paper's tapered monolith, rigid (every method takes it).
COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1}
#: A drift of the acceleration [m/s^2, m/s^3, m/s^4]: metres of displacement in 30 s.
DRIFT = (0.02, 0.001, 2e-5)


def _clean():
    rec = read_record(CLEAN)
    return rec.t, rec.acceleration


def _drift_displacement(t, c):
    """Closed form: displacement from rest of c0 + c1 t + c2 t^2 [m]."""
    return c[0] * t**2 / 2 + c[1] * t**3 / 6 + c[2] * t**4 / 12


# --------------------------------------------------------------------------- baseline


@pytest.mark.parametrize("baseline, degree", [("linear", 1), ("quadratic", 2)])
def test_a_drift_is_removed_by_its_baseline(baseline, degree):
    t, a = _clean()
    c = DRIFT[: degree + 1] + (0.0,) * (2 - degree)
    drifted = a + c[0] + c[1] * t + c[2] * t**2
    u_clean = displacement_at_samples(t, a)
    u_drift = displacement_at_samples(t, drifted)
    # the drift's displacement is its closed form (exact for a polynomial of degree <= 1;
    # the quadratic's cubic interpolation errs by c2 h^2 t^2 / 12 at most)
    assert u_drift[-1] - u_clean[-1] == pytest.approx(_drift_displacement(t[-1], c), rel=1e-6)
    assert abs(u_drift[-1]) > 10.0  # metres of drift
    assert abs(u_clean[-1]) < 1e-3  # the clean record returns near zero
    corrected = displacement_at_samples(t, remove_baseline(t, drifted, baseline))
    # back near zero, near the clean record's (the fit also takes the part of the clean
    # record's own slow displacement that a polynomial follows: 4 mm linear, 2 cm quadratic)
    assert abs(corrected[-1]) < 0.03 and abs(corrected[-1] - u_clean[-1]) < 0.03
    assert np.max(np.abs(corrected)) < 1.1 * np.max(np.abs(u_clean))
    assert (
        np.max(np.abs(corrected - displacement_at_samples(t, remove_baseline(t, a, baseline))))
        < 1e-9
    )


def test_a_linear_baseline_does_not_remove_a_quadratic_drift():
    """The degree matters: a t^2 drift survives a linear baseline (the test can fail)."""
    t, a = _clean()
    drifted = a + DRIFT[2] * t**2  # 1.35 m of displacement in 30 s

    def left(baseline):  # what the drift leaves: beyond the clean record's correction
        ours = displacement_at_samples(t, remove_baseline(t, drifted, baseline))
        return np.max(np.abs(ours - displacement_at_samples(t, remove_baseline(t, a, baseline))))

    assert left("linear") > 0.02
    assert left("quadratic") < 1e-9


@pytest.mark.parametrize("baseline, degree", [("linear", 1), ("quadratic", 2)])
def test_a_polynomial_is_removed_to_round_off(baseline, degree):
    """A record that is a polynomial of the baseline's degree is all baseline: 0 is left."""
    t = np.sort(np.random.default_rng(3).uniform(0.2, 12.0, 900))  # uneven steps, t0 > 0
    a = 0.3 - 0.05 * t + (0.004 * t**2 if degree == 2 else 0.0)
    assert np.max(np.abs(remove_baseline(t, a, baseline))) < 1e-10


def test_baseline_fit_against_analytic_displacements():
    """The fit's polynomial equals a least-squares fit made here: the analytic displacement
    of each power of time, t^(j+2) / ((j+1)(j+2)), fitted to the record's displacement
    integrated by the trapezoid rule twice (a second integration) on a fine resampling."""
    t, a = _clean()
    drifted = a + 0.02 + 0.001 * t - 3e-5 * t**2
    ours = baseline_fit(t, drifted, 2)
    fine = np.linspace(t[0], t[-1], 10 * (t.size - 1) + 1)
    af = np.interp(fine, t, drifted)
    u = cumulative_trapezoid(cumulative_trapezoid(af, fine, initial=0.0), fine, initial=0.0)
    basis = np.column_stack([fine ** (j + 2) / ((j + 1) * (j + 2)) for j in range(3)])
    coef, *_ = np.linalg.lstsq(basis, u, rcond=None)
    theirs = coef[0] + coef[1] * t + coef[2] * t**2
    assert np.max(np.abs(ours - theirs)) < 1e-4 * np.max(np.abs(theirs))


# --------------------------------------------------------------------------- band-pass


def _gain(f, low, high, order, fs):
    """filtfilt's gain: the digital Butterworth |H|^2 of each side (bilinear, prewarped)."""
    w = np.tan(np.pi * f / fs)
    hp = 1.0 / (1.0 + (np.tan(np.pi * low / fs) / w) ** (2 * order))
    lp = 1.0 / (1.0 + (w / np.tan(np.pi * high / fs)) ** (2 * order))
    return hp * lp


def _amplitude_phase(t, x, f):
    """Amplitude and phase of the sine of frequency f in x, by least squares."""
    basis = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])
    (s, c), *_ = np.linalg.lstsq(basis, x, rcond=None)
    return float(np.hypot(s, c)), float(np.arctan2(c, s))


@pytest.mark.parametrize("order", [2, 4])
@pytest.mark.parametrize("f", [0.5, 1.0, 3.0, 8.0, 15.0])
def test_band_pass_keeps_a_sine_inside_with_its_gain(f, order):
    fs, low, high = 100.0, 0.5, 15.0
    t = np.arange(12001) / fs
    x = np.sin(2 * np.pi * f * t + 0.3)
    y = band_pass(t, x, low, high, order)
    mid = (t > 30.0) & (t < 90.0)  # away from the ends' transients
    amp, phase = _amplitude_phase(t[mid], y[mid], f)
    expected = _gain(f, low, high, order, fs)
    assert amp == pytest.approx(expected, abs=1e-9)  # measured: 4e-14
    assert phase == pytest.approx(0.3, abs=1e-9)  # zero phase (measured: 1.4e-13 rad)
    # the analogue gain |H|^2 = 1 / (1 + (f / f_c)^(2n)) a side (one pass's |H|, twice):
    # close to the digital one well below fs
    analogue = 1 / (1 + (low / f) ** (2 * order)) / (1 + (f / high) ** (2 * order))
    assert amp == pytest.approx(analogue, abs=0.03)


@pytest.mark.parametrize("f", [0.05, 0.1, 35.0, 45.0])
def test_band_pass_removes_a_sine_outside(f):
    fs, low, high, order = 100.0, 0.5, 10.0, 4
    t = np.arange(30001) / fs
    y = band_pass(t, np.sin(2 * np.pi * f * t), low, high, order)
    mid = (t > 50.0) & (t < 250.0)
    amp, _ = _amplitude_phase(t[mid], y[mid], f)
    assert _gain(f, low, high, order, fs) < 1e-4
    assert amp < 1e-5  # measured: 2.6e-6 at most


def test_band_pass_refuses_uneven_steps():
    t = np.sort(np.random.default_rng(1).uniform(0.0, 10.0, 500))
    with pytest.raises(Exception, match="even time steps"):
        band_pass(t, np.sin(t), 0.5, 5.0, 4)


# --------------------------------------------------------------------------- config


def _config(tmp_path, processing, file="r.AT2", **extra):
    excitation = {"type": "record", "file": file, "processing": processing, **extra}
    return parse_config({"name": "p", "column": COLUMN, "excitation": excitation},
                        "c.yaml", tmp_path)  # fmt: skip


@pytest.fixture
def folder(tmp_path):
    t, a = _clean()
    write_at2(tmp_path / "r.AT2", a + 0.02 + 0.001 * t, dt=0.01)  # drifting, dt 0.01 s
    write_at2(tmp_path / "v.AT2", 0.5 * a[::-1], dt=0.01)
    write_at2(tmp_path / "short.AT2", a[:20], dt=0.01)
    tu = np.sort(np.concatenate([[0.0, 5.0], np.random.default_rng(2).uniform(0, 5, 300)]))
    write_csv(tmp_path / "uneven.csv", (tu, np.sin(3 * tu)), units="m/s2")
    return tmp_path


BAND = {"low_hz": 0.1, "high_hz": 10}
ORDER_RANGE = "filter.order must be an integer in 1..8"


@pytest.mark.parametrize(
    "processing, extra, needle",
    [
        ({"baseline": "cubic"}, {}, "excitation.processing.baseline must be one of"),
        ({"smooth": 1}, {}, "unknown key 'smooth' in excitation.processing"),
        ("linear", {}, "excitation.processing must be a mapping"),
        ({"filter": {"high_hz": 10}}, {}, "excitation.processing.filter.low_hz is required"),
        ({"filter": {"low_hz": 0.1}}, {}, "excitation.processing.filter.high_hz is required"),
        ({"filter": {**BAND, "q": 1}}, {}, "unknown key 'q'"),
        ({"filter": {**BAND, "order": 0}}, {}, ORDER_RANGE),
        ({"filter": {**BAND, "order": 9}}, {}, ORDER_RANGE),
        ({"filter": {**BAND, "order": 2.5}}, {}, "filter.order must be an integer"),
        ({"filter": {"low_hz": 0, "high_hz": 10}}, {}, "filter.low_hz must be a number > 0"),
        ({"filter": {"low_hz": -1, "high_hz": 10}}, {}, "filter.low_hz must be a number > 0"),
        ({"filter": {"low_hz": 5, "high_hz": 5}}, {}, "filter.high_hz must be above"),
        ({"filter": {"low_hz": 0.1, "high_hz": 50}}, {}, "below the Nyquist frequency of"),
        ({"filter": {"low_hz": 0.1, "high_hz": float("nan")}}, {}, "filter.high_hz must be"),
        ({"filter": BAND}, {"file": "uneven.csv", "units": "m/s2"}, "uneven time steps"),
        ({"filter": BAND}, {"file": "short.AT2"}, "filter.order: excitation.file"),
        ({"filter": BAND}, {"vertical": "uneven.csv"}, "excitation.vertical ("),
    ],
)
def test_bad_processing_is_one_line(folder, processing, extra, needle):
    with pytest.raises(ConfigError) as err:
        _config(folder, processing, **extra)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_processing_of_another_type_refused(folder):
    with pytest.raises(ConfigError, match="excitation.processing applies only to type record"):
        excitation = {"type": "half-sine", "processing": {"baseline": "linear"}}
        parse_config({"name": "p", "column": COLUMN, "excitation": excitation})


def test_uneven_steps_take_a_baseline(folder):
    cfg = _config(folder, {"baseline": "quadratic"}, file="uneven.csv", units="m/s2")
    assert cfg.excitation.processing.baseline == "quadratic"


def test_processing_in_the_hash(folder):
    """Processing enters the config's hash; none (or baseline none) hashes as no key."""
    excitation = {"type": "record", "file": "r.AT2"}
    bare = parse_config({"name": "p", "column": COLUMN, "excitation": excitation}, "c.yaml", folder)
    none = _config(folder, {"baseline": "none"})
    assert none.excitation.processing is None and config_hash(none) == config_hash(bare)
    hashes = {
        config_hash(_config(folder, p))
        for p in (
            {"baseline": "linear"},
            {"baseline": "quadratic"},
            {"filter": {"low_hz": 0.1, "high_hz": 20}},
            {"filter": {"low_hz": 0.1, "high_hz": 20, "order": 2}},
            {"filter": {"low_hz": 0.2, "high_hz": 20}},
        )
    }
    assert len(hashes) == 5 and config_hash(bare) not in hashes


def test_a_resume_over_other_processing_is_refused(folder):
    text = (
        "name: p\ncolumn: {}\nexcitation: {{type: record, file: r.AT2, processing: {}}}\n"
        "grid: {{amplitudes: [0.3]}}\n"
    )
    (folder / "a.yaml").write_text(text.format(json.dumps(COLUMN), "{baseline: linear}"))
    (folder / "b.yaml").write_text(text.format(json.dumps(COLUMN), "{baseline: quadratic}"))
    out = str(folder / "out")
    first = CliRunner().invoke(cli, ["sweep", str(folder / "a.yaml"), "-o", out, "-j", "1"])
    assert first.exit_code == 0, first.output
    again = CliRunner().invoke(
        cli, ["sweep", str(folder / "b.yaml"), "-o", out, "-j", "1", "--resume"]
    )
    assert again.exit_code != 0
    assert "Traceback" not in again.output


# --------------------------------------------------------------------------- motion


def test_pga_scaling_uses_the_processed_record(folder):
    band = {"filter": {"low_hz": 0.2, "high_hz": 2.0}, "baseline": "linear"}
    cfg = _config(folder, band)
    motion = make_ground_motion(cfg.excitation, 0.3)
    t, a = _clean()
    raw = a + 0.02 + 0.001 * t
    assert np.max(np.abs(motion.values)) == pytest.approx(0.3 * G, rel=1e-12)
    # the processing changed the PGA, so scaling to the raw record's PGA would miss 0.3 g
    processed = process(t, raw, cfg.excitation.processing)
    assert abs(np.max(np.abs(raw)) / np.max(np.abs(processed)) - 1.0) > 0.05
    # the band holds nothing above 2 Hz: the spectrum's energy there is tiny
    spectrum = np.abs(np.fft.rfft(motion.values))
    freqs = np.fft.rfftfreq(motion.values.size, 0.01)
    assert np.sum(spectrum[freqs > 6.0] ** 2) < 1e-6 * np.sum(spectrum**2)
    # and the ground displacement at the record's end is back near zero
    assert abs(motion.displacement(np.array([t[-1]]))[0]) < 0.05


def test_the_vertical_record_is_processed_the_same_way(folder):
    cfg = _config(folder, {"baseline": "linear", "filter": {"low_hz": 0.2, "high_hz": 2.0}},
                  vertical="v.AT2")  # fmt: skip
    motion = make_ground_motion(cfg.excitation, 0.3)
    t, a = _clean()
    raw_v = 0.5 * a[::-1]
    assert np.array_equal(motion.knots, t)  # same samples: the knots are theirs
    spectrum = np.abs(np.fft.rfft(motion.vertical))
    freqs = np.fft.rfftfreq(motion.vertical.size, 0.01)
    assert np.sum(spectrum[freqs > 6.0] ** 2) < 1e-6 * np.sum(spectrum**2)
    raw_spectrum = np.abs(np.fft.rfft(raw_v))
    assert np.sum(raw_spectrum[freqs > 6.0] ** 2) > 1e-3 * np.sum(raw_spectrum**2)
    # scaled by the horizontal's factor: the peaks' ratio is the processed records'
    p = cfg.excitation.processing
    ratio = np.max(np.abs(process(t, raw_v, p))) / np.max(
        np.abs(process(t, a + 0.02 + 0.001 * t, p))
    )
    assert np.max(np.abs(motion.vertical)) / np.max(np.abs(motion.values)) == pytest.approx(ratio)


# --------------------------------------------------------------------------- runs


@pytest.fixture(scope="module")
def drifting(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drift")
    t, a = _clean()
    write_at2(folder / "r.AT2", a + 0.02 + 0.001 * t, dt=0.01)
    return folder


def _run(folder, method, processing, name):
    excitation = {"type": "record", "file": "r.AT2"}
    if processing is not None:
        excitation["processing"] = processing
    solver = {"method": method}
    if method == "exact":  # its own source uncompiled (the same bits): no compile here
        solver["implementation"] = "python"
    data = {"name": name, "column": COLUMN, "excitation": excitation, "solver": solver}
    (folder / f"{name}.yaml").write_text(json.dumps(data))
    out = folder / "out"
    res = CliRunner().invoke(
        cli, ["run", str(folder / f"{name}.yaml"), "-a", "0.3", "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    run = next((out / name).glob("run_*"))
    summary = json.loads((run / "summary.json").read_text())
    history = np.genfromtxt(run / "history.csv", delimiter=",", names=True)
    return summary, history


PROCESSING = {"baseline": "linear", "filter": {"low_hz": 0.1, "high_hz": 20.0}}


@pytest.fixture(scope="module")
def raw_run(drifting):
    return _run(drifting, "auto", None, "raw")


@pytest.fixture(scope="module")
def exact_run(drifting):
    return _run(drifting, "exact", PROCESSING, "exact_reference")


@pytest.mark.parametrize("method", [m for m in METHODS if m != "exact-first"])  # elastic only
def test_rbm_run_of_a_processed_record_with_every_method(drifting, raw_run, exact_run, method):
    """Every method runs the processed record, and agrees with the exact integrator."""
    summary, history = _run(drifting, method, PROCESSING, f"m_{method}")
    reference = exact_run[0]
    assert summary["status"] == reference["status"]
    assert summary["max_rotation_ratio"] == pytest.approx(reference["max_rotation_ratio"], rel=2e-2)
    end = history["t_s"] <= 30.0
    assert np.max(np.abs(history["ug_m"][end])) < 0.5  # processed: no drift
    raw_summary, raw_history = raw_run
    # the raw record drifts by its closed form, scaled to 0.3 g over the raw PGA
    raw_end = np.argmin(np.abs(raw_history["t_s"] - 30.0))
    assert abs(raw_history["ug_m"][raw_end]) > 5.0


def test_a_motion_given_as_arrays_is_processed_as_its_file(folder):
    """The same samples given as arrays (rbm.motion_from_arrays) and as a file: the same
    processed motion."""
    from rbm_cli.config.motions import motion_from_arrays

    t, a = _clean()
    raw = read_record(folder / "r.AT2")
    motion = motion_from_arrays(raw.t, raw.acceleration, units="m/s2", name="arrays")
    band = {"baseline": "quadratic", "filter": {"low_hz": 0.2, "high_hz": 8.0, "order": 3}}
    from_file = make_ground_motion(_config(folder, band).excitation, 0.4)
    from_arrays = make_ground_motion(_config(folder, band, file=motion).excitation, 0.4)
    assert np.array_equal(from_file.values, from_arrays.values)
    assert np.max(np.abs(from_arrays.values)) == pytest.approx(0.4 * G, rel=1e-12)


# --------------------------------------------------------------------------- figures


def _history(ground_m, top_m):
    from rbm_cli.models.history import History

    t = np.linspace(0.0, 10.0, 501)
    rel = top_m * np.sin(2 * np.pi * t)
    nodes = np.column_stack([np.zeros_like(t), rel])
    return History(t, np.zeros_like(t), ground_m * (t / 10.0) ** 2, nodes, rel[:, None] / 5.0)


@pytest.mark.parametrize(
    "ground, relative, drawn_relative",
    [(10.0, None, True), (0.05, None, False), (10.0, False, False), (0.05, True, True)],
)
def test_a_drifting_ground_is_drawn_relative(ground, relative, drawn_relative):
    """A ground moving 10 m under a column rocking by 0.1 m: the top is drawn relative to
    the ground, the ground on a right axis of its own; 5 cm: both on one scale."""
    from rbm_cli.report.plots import ground_drifts, plot_history

    history = _history(ground, 0.1)
    assert ground_drifts(history) == (ground == 10.0)
    ax = plot_history(history, relative=relative)
    twins = [a for a in ax.figure.axes if a is not ax]
    assert bool(twins) == drawn_relative
    if drawn_relative:
        (line,) = [ln for ln in twins[0].get_lines() if ln.get_gid() == "ground"]
        assert np.max(line.get_ydata()) == pytest.approx(ground)
        top = [ln for ln in ax.get_lines() if "top" in ln.get_label()][0]
        assert np.max(np.abs(top.get_ydata())) == pytest.approx(0.1, rel=5e-3)
