"""Ground-motion records: reading PEER NGA .AT2 and CSV files, writing them, interpolation.

Expected values come from what the files say (hand-written numbers, closed forms of the
sampled signals), never from the reader's own output.
"""

import math
import time

import numpy as np
import pytest

from rbm_cli.base.errors import RbmError
from rbm_cli.config import record_files as record_parsers
from rbm_cli.inputs.records import G, Record, read_record, write_at2, write_csv

HEADER = [
    "PEER NGA STRONG MOTION DATABASE RECORD",
    "Test event 2001, Test station, 090",
    "ACCELERATION TIME SERIES IN UNITS OF G",
]


def _at2(tmp_path, line4, body, name="rec.AT2", header=HEADER):
    path = tmp_path / name
    path.write_text("\n".join([*header, line4, *body]) + "\n")
    return path


# --------------------------------------------------------------------------- AT2


@pytest.mark.parametrize(
    "line4",
    [
        "NPTS=  7, DT=   .0050 SEC",
        "NPTS= 7 DT= 0.005",
        "npts=7,dt=.005 sec",
        "NPTS=      7, DT=   .50000E-02 SEC",
        "   7    0.0050    NPTS, DT",
        "7 .005 NPTS, DT",
    ],
)
def test_at2_header_styles(tmp_path, line4):
    """Both header styles in use (and spacing variants) give NPTS = 7, DT = 0.005 s."""
    body = ["  .1000000E+00 -.2000000E+00  .3000000E-01", "  .0 1.0D-02", "-.123E-02   5E-1"]
    rec = read_record(_at2(tmp_path, line4, body))
    expected_g = [0.1, -0.2, 0.03, 0.0, 0.01, -0.00123, 0.5]
    np.testing.assert_allclose(rec.t, 0.005 * np.arange(7), rtol=0, atol=1e-15)
    np.testing.assert_allclose(rec.acceleration, np.array(expected_g) * 9.81, rtol=1e-15)
    assert rec.name == "rec"
    assert rec.title == "Test event 2001, Test station, 090"
    assert rec.t[0] == 0.0


def test_at2_any_count_per_line(tmp_path):
    """Lines of 1, 3 and 8 values; blank lines between them are ignored."""
    vals = np.arange(1, 13) / 100.0
    body = [
        f"{vals[0]:.2f}",
        "",
        " ".join(f"{v:.2f}" for v in vals[1:4]),
        " ".join(f"{v:.2f}" for v in vals[4:]),
    ]
    rec = read_record(_at2(tmp_path, "NPTS= 12, DT= 0.01 SEC", body))
    np.testing.assert_allclose(rec.acceleration / G, vals, rtol=1e-15)


@pytest.mark.parametrize("style", ["new", "old"])
def test_at2_round_trip(tmp_path, style):
    """write_at2 then read_record: 8 significant digits in g, times exact multiples of DT."""
    rng = np.random.default_rng(3)
    a = rng.normal(scale=2.0, size=1234)  # m/s^2
    path = write_at2(tmp_path / "r.at2", a, dt=0.02, header_style=style, values_per_line=7)
    rec = read_record(path)
    assert len(rec) == 1234
    np.testing.assert_array_equal(rec.t, np.arange(1234) * 0.02)
    np.testing.assert_allclose(rec.acceleration, a, rtol=5e-8, atol=0)


def test_at2_record_round_trip_keeps_title(tmp_path):
    rec = Record.from_samples([0.0, 1.0, -2.0, 0.5], dt=0.1, name="x", title="event A")
    back = read_record(write_at2(tmp_path / "x.AT2", rec))
    assert back.title == "event A"
    np.testing.assert_allclose(back.acceleration, rec.acceleration, rtol=1e-8)


def test_at2_big_file_fast(tmp_path):
    """60,000 samples (5 a line) parse in well under a second and exactly."""
    n = 60_000
    a_g = np.sin(np.arange(n) * 0.01) * 0.3
    body = ["".join(f"{v:15.7E}" for v in a_g[i : i + 5]) for i in range(0, n, 5)]
    path = _at2(tmp_path, f"NPTS= {n}, DT= .0050 SEC", body)
    start = time.perf_counter()
    rec = read_record(path)
    elapsed = time.perf_counter() - start
    assert len(rec) == n
    np.testing.assert_allclose(rec.acceleration / G, a_g, rtol=1e-7, atol=1e-12)
    assert elapsed < 2.0, elapsed


# --------------------------------------------------------------------------- CSV


def test_csv_units_and_uneven_steps(tmp_path):
    """Uneven steps kept; g converted with g = 9.81; m/s2 kept; extra columns ignored."""
    text = "# a comment\ntime_s,acc,extra\n0,0.1,x\n0.01,0.2,y\n\n0.035,-0.1,z\n0.04,0,w\n"
    path = tmp_path / "r.csv"
    path.write_text(text)
    rec_g = read_record(path)
    rec_si = read_record(path, units="m/s2")
    np.testing.assert_array_equal(rec_g.t, [0.0, 0.01, 0.035, 0.04])
    np.testing.assert_allclose(rec_g.acceleration, np.array([0.1, 0.2, -0.1, 0.0]) * 9.81)
    np.testing.assert_allclose(rec_si.acceleration, [0.1, 0.2, -0.1, 0.0])
    assert rec_g.pga == pytest.approx(0.2 * 9.81)


def test_csv_late_start_is_rest_before(tmp_path):
    """A first time > 0: the ground is at rest before it, the clock is not shifted."""
    path = tmp_path / "late.csv"
    path.write_text("t,a\n1.0,0.5\n1.5,0.5\n2.0,0.0\n")
    rec = read_record(path)
    assert rec.t[0] == 1.0
    assert rec.duration == 2.0
    assert rec.at(0.5) == 0.0
    assert rec.at(0.999999) == 0.0
    assert rec.at(1.0) == pytest.approx(0.5 * 9.81)
    assert rec.at(1.75) == pytest.approx(0.25 * 9.81)
    assert rec.at(2.5) == 0.0


@pytest.mark.parametrize("units", ["g", "m/s2"])
def test_csv_round_trip_exact(tmp_path, units):
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.001, 0.02, size=500))
    a = rng.normal(size=500)
    rec = read_record(write_csv(tmp_path / "r.csv", (t, a), units=units), units=units)
    np.testing.assert_array_equal(rec.t, t)
    if units == "m/s2":
        np.testing.assert_array_equal(rec.acceleration, a)
    else:
        np.testing.assert_allclose(rec.acceleration, a, rtol=2e-16)


# --------------------------------------------------------------------------- Record


def test_interpolation_linear_and_zero_outside():
    """Linear data are reproduced exactly between samples; 0 before and after."""
    t = np.array([0.0, 0.1, 0.3, 0.6])
    rec = Record(t, 2.0 * t - 0.25)
    q = np.linspace(0.0, 0.6, 37)
    np.testing.assert_allclose(rec.at(q), 2.0 * q - 0.25, atol=1e-15)
    assert rec.at(-1e-9) == 0.0 and rec.at(0.6 + 1e-9) == 0.0
    assert isinstance(rec.at(0.2), float)
    assert rec.pga == pytest.approx(0.95)
    assert rec.duration == 0.6


@pytest.mark.parametrize("fmt", ["at2", "csv"])
def test_sampled_half_sine_interpolation_bound(tmp_path, fmt):
    """A half-sine written and read back: |at(t) - A sin(w t)| <= dt^2/8 A w^2 (+ digits).

    The bound is the linear-interpolation error of a function with |a''| <= A w^2; the
    maximal error must also come close to it (the interpolation is linear, not better).
    """
    amp, freq, dt = 0.4 * G, 1.25, 0.005  # half period 0.4 s = 80 steps
    w = 2 * math.pi * freq
    n = int(round(0.5 / freq / dt))
    t = np.arange(n + 1) * dt
    a = amp * np.sin(w * t)
    a[-1] = 0.0
    if fmt == "at2":
        rec = read_record(write_at2(tmp_path / "hs.AT2", a, dt=dt))
    else:
        rec = read_record(write_csv(tmp_path / "hs.csv", (t, a)))
    q = np.linspace(0, 0.5 / freq, 20001)
    err = np.max(np.abs(rec.at(q) - amp * np.sin(w * q)))
    bound = dt**2 / 8 * amp * w**2
    assert err <= bound * (1 + 1e-3) + 1e-7 * amp
    assert err >= 0.9 * bound


def test_record_is_frozen_and_read_only():
    rec = Record.from_samples([0.0, 1.0], dt=0.1)
    with pytest.raises(ValueError):
        rec.acceleration[0] = 3.0
    with pytest.raises(AttributeError):
        rec.name = "other"
    scaled = rec.scaled(2.0)
    assert scaled.pga == 2.0 and rec.pga == 1.0


@pytest.mark.parametrize(
    ("t", "a", "fragment"),
    [
        ([0.0, 0.1, 0.1], [0, 1, 2], "must increase"),
        ([0.0, 0.2, 0.1], [0, 1, 2], "must increase"),
        ([-0.1, 0.2], [0, 1], ">= 0"),
        ([0.0], [1.0], "at least 2"),
        ([0.0, 1.0], [0.0, np.nan], "finite"),
        ([0.0, 1.0], [0.0], "1 accelerations"),
    ],
)
def test_record_refuses_bad_arrays(t, a, fragment):
    with pytest.raises(RbmError, match=fragment):
        Record(t, a, name="r")


# --------------------------------------------------------------------------- refusals

GOOD = ["0.1 0.2 0.3"]

AT2_CASES = {
    "empty file": ("", "empty file"),
    "blank file": ("\n\n \n", "empty file"),
    "three header lines": ("\n".join(HEADER) + "\n", "line 4: missing header line"),
    "bad header": ("\n".join([*HEADER, "5000 points at 0.005 s", *GOOD]), "line 4: expected"),
    "no dt": ("\n".join([*HEADER, "NPTS= 3", *GOOD]), "line 4: expected"),
    "npts fewer": ("\n".join([*HEADER, "NPTS= 4, DT= .01 SEC", *GOOD]), "line 4: NPTS = 4"),
    "npts more": (
        "\n".join([*HEADER, "NPTS= 2, DT= .01 SEC", "0.1", "0.2 0.3"]),
        "line 6: more values than NPTS = 2",
    ),
    "nan": ("\n".join([*HEADER, "NPTS= 3, DT= .01 SEC", "0.1 0.2", "NaN"]), "line 6: non-fin"),
    "inf": ("\n".join([*HEADER, "NPTS= 3, DT= .01 SEC", "0.1 -inf 0.2"]), "line 5: non-fin"),
    "non-numeric": (
        "\n".join([*HEADER, "NPTS= 3, DT= .01 SEC", "0.1 0.2", "", "0.3x"]),
        "line 7: not a number: '0.3x'",
    ),
    "dt zero": ("\n".join([*HEADER, "NPTS= 3, DT= 0.0 SEC", *GOOD]), "line 4: DT must be > 0"),
    "dt negative": ("\n".join([*HEADER, "   3   -0.01   NPTS, DT", *GOOD]), "line 4: DT must"),
    "dt text": ("\n".join([*HEADER, "NPTS= 3, DT= fast SEC", *GOOD]), "line 4: DT must be a n"),
    "npts float": ("\n".join([*HEADER, "NPTS= 3.5, DT= .01", *GOOD]), "line 4: NPTS must be an"),
    "npts one": ("\n".join([*HEADER, "NPTS= 1, DT= .01", "0.1"]), "line 4: NPTS must be >= 2"),
    "npts huge": ("\n".join([*HEADER, "NPTS= 20000000, DT= .01", *GOOD]), "line 4: NPTS = 2000"),
    "velocity": (
        "\n".join([*HEADER[:2], "VELOCITY TIME SERIES IN UNITS OF CM/S", "NPTS= 3, DT= .01"]),
        "line 3: a velocity time series",
    ),
    "units": (
        "\n".join([*HEADER[:2], "ACCELERATION IN UNITS OF CM/S2", "NPTS= 3, DT= .01", *GOOD]),
        "line 3: values must be in units of G",
    ),
}

CSV_CASES = {
    "empty file": ("", "empty file"),
    "only comments": ("# nothing\n\n", "empty file"),
    "header only": ("t,a\n", "at least 2 data rows after the header, has 0"),
    "one row": ("t,a\n0,1\n", "at least 2 data rows after the header, has 1"),
    "no header": ("0,0.1\n0.01,0.2\n", "line 1: missing header row"),
    "one column header": ("time\n0\n1\n", "line 1: expected at least 2 columns"),
    "one column row": ("t,a\n0,1\n0.01\n", "line 3: expected at least 2 columns"),
    "non-numeric": ("t,a\n0,1\n0.01,abc\n", "line 3: not a number: 'abc'"),
    "empty field": ("t,a\n0,1\n0.01,\n", "line 3: not a number: ''"),
    "nan": ("t,a\n0,1\n\n0.01,nan\n", "line 4: non-finite"),
    "inf time": ("t,a\n0,1\ninf,0\n", "line 3: non-finite"),
    "equal times": ("t,a\n0,1\n0.01,2\n0.01,3\n", "line 4: time must increase"),
    "decreasing": ("t,a\n0,1\n0.02,2\n0.01,3\n", "line 4: time must increase"),
    "negative time": ("t,a\n-0.01,1\n0.02,2\n", "line 2: time must be >= 0"),
}


def _check_refusal(path, fragment, **kwargs):
    with pytest.raises(RbmError) as info:
        read_record(path, **kwargs)
    msg = str(info.value)
    assert "\n" not in msg
    assert str(path) in msg
    assert fragment in msg, msg


@pytest.mark.parametrize("case", sorted(AT2_CASES))
def test_malformed_at2_refused_in_one_line(tmp_path, case):
    text, fragment = AT2_CASES[case]
    path = tmp_path / "bad.AT2"
    path.write_text(text)
    _check_refusal(path, fragment)


@pytest.mark.parametrize("case", sorted(CSV_CASES))
def test_malformed_csv_refused_in_one_line(tmp_path, case):
    text, fragment = CSV_CASES[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    _check_refusal(path, fragment)


def test_other_refusals(tmp_path, monkeypatch):
    csv = tmp_path / "ok.csv"
    csv.write_text("t,a\n0,1\n1,2\n")
    at2 = _at2(tmp_path, "NPTS= 3, DT= .01", GOOD)
    _check_refusal(csv, "units must be 'g' or 'm/s2', got 'cm/s2'", units="cm/s2")
    _check_refusal(at2, "an .AT2 file is in g", units="m/s2")
    _check_refusal(tmp_path / "missing.AT2", "no such file")
    txt = tmp_path / "rec.txt"
    txt.write_text("t,a\n0,1\n1,2\n")
    _check_refusal(txt, "unknown record format 'txt'")
    assert read_record(txt, fmt="csv").pga == pytest.approx(2 * G)
    folder = tmp_path / "folder.csv"
    folder.mkdir()
    _check_refusal(folder, "is a folder")
    monkeypatch.setattr(record_parsers, "MAX_FILE_BYTES", 10)
    _check_refusal(csv, "more than the 10 bytes")
    monkeypatch.setattr(record_parsers, "MAX_FILE_BYTES", 10**6)
    monkeypatch.setattr(record_parsers, "MAX_SAMPLES", 1)
    _check_refusal(csv, "more than the 1 samples allowed")


def test_write_refusals(tmp_path):
    uneven = Record([0.0, 0.1, 0.3], [0.0, 1.0, 0.0])
    with pytest.raises(RbmError, match="t = k DT"):
        write_at2(tmp_path / "u.AT2", uneven)
    with pytest.raises(RbmError, match="dt"):
        write_at2(tmp_path / "u.AT2", [0.0, 1.0])
    with pytest.raises(RbmError, match="units"):
        write_csv(tmp_path / "u.csv", uneven, units="cm")


def test_windows_line_ends_tabs_and_bom(tmp_path):
    """CRLF line ends, tab separators (AT2) and a UTF-8 byte-order mark (CSV) are read."""
    at2 = tmp_path / "crlf.AT2"
    lines = [*HEADER, "NPTS= 4, DT= 0.02 SEC", "0.1\t-0.2", "  .3E-01\t0.0"]
    at2.write_bytes("\r\n".join(lines).encode() + b"\r\n")
    rec = read_record(at2)
    np.testing.assert_allclose(rec.acceleration / G, [0.1, -0.2, 0.03, 0.0], rtol=1e-15)
    csv = tmp_path / "bom.csv"
    csv.write_bytes(b"\xef\xbb\xbftime_s,acc_g\r\n0,0.5\r\n0.5,0.25\r\n")
    rec = read_record(csv)
    np.testing.assert_array_equal(rec.t, [0.0, 0.5])
    assert rec.at(0.25) == pytest.approx(0.375 * G)
