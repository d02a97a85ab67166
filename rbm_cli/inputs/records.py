"""Ground-motion records: PEER NGA ``.AT2`` and CSV accelerograms, read, checked and written.

A :class:`Record` holds the horizontal ground acceleration a_g(t) [m/s^2] (SI inside) at
strictly increasing sample times t [s]. Its conventions, which the integrator relies on:

- **Sign.** A positive value is a ground acceleration in the +x direction of the model, the
  same a_g as the harmonic and half-sine excitations.
- **Clock.** The simulation starts at t = 0. An ``.AT2`` record's k-th value (k = 0, 1, ...)
  is at t = k DT, so its first sample is at t = 0. A CSV record keeps the times of its file
  (no shift); a first time > 0 means the ground is at rest before it: :meth:`Record.at`
  is 0 before the first sample and after the last one, and linear in between. So a record
  whose first or last value is not 0 starts or ends with a jump of the acceleration (the
  integrator must restart there). Negative times are refused.
- **Duration.** :attr:`Record.duration` is the time of the last sample, measured from
  t = 0 (not from the first sample).

Processing (``excitation.processing``) is a function of the samples (t, a):
:func:`process` band-passes (:func:`band_pass`) and then removes a baseline
(:func:`remove_baseline`); :meth:`Record.processed` gives the record it makes.

Reading is strict: every malformed file is refused with an :class:`~rbm_cli.base.errors.RbmError`
whose one-line message names the file and, where there is one, the line. Files are parsed
in blocks of lines with numpy (:mod:`rbm_cli.config.record_files`), so memory stays bounded;
files of more than 10^7 samples or 512 MiB are refused before they are read.

References
----------
.. [1] PEER NGA strong motion database: file format of the ``.AT2`` acceleration time
   series (four header lines, then the values in g). Pacific Earthquake Engineering
   Research Center, https://ngawest2.berkeley.edu.
.. [2] Boore, D. M. and Bommer, J. J. (2005). Processing of strong-motion accelerograms:
   needs, options and consequences. Soil Dynamics and Earthquake Engineering 25, 93-115
   (baseline corrections fitted to the velocity or displacement; acausal, zero-phase
   Butterworth filters); Ancheta, T. D. et al. (2014), NGA-West2 database, Earthquake
   Spectra 30(3), 989-1005 (filtering, then a polynomial fitted to the displacement).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config import record_files as record_parsers
from rbm_cli.config.excitation import filter_padding
from rbm_cli.config.types import BASELINES, G, ProcessingConfig  # G: the one definition

_UNITS = record_parsers.UNITS


@dataclass(frozen=True, eq=False)
class Record:
    """A horizontal ground-acceleration record, SI units.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, t[0] >= 0, at least two samples
    acceleration : array_like
        Ground acceleration at the sample times [m/s^2], finite; positive in +x
    name : str
        Short name (the file stem for a record read from a file)
    source : str
        Where it comes from (a file path, or a description)
    title : str
        Free text (line 2 of an ``.AT2`` header: event, station, component)

    Notes
    -----
    Between samples the acceleration is linear; before the first and after the last
    sample it is 0 (see the module docstring for the clock):

    .. math:: a_g(t) = a_k + (a_{k+1} - a_k) (t - t_k) / (t_{k+1} - t_k),
              \\quad t_k \\le t \\le t_{k+1}

    Examples
    --------
    >>> rec = Record.from_samples([0.0, 1.0, 0.0], dt=0.5, name="tri")
    >>> rec.at(0.25), rec.pga, rec.duration
    (0.5, 1.0, 1.0)
    """

    t: np.ndarray
    acceleration: np.ndarray
    name: str = "record"
    source: str = ""
    title: str = field(default="")

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float, copy=True).ravel()
        a = np.array(self.acceleration, dtype=float, copy=True).ravel()
        where = f"record {self.name!r}"
        if t.size != a.size:
            raise RbmError(f"{where}: {t.size} times but {a.size} accelerations")
        if t.size < 2:
            raise RbmError(f"{where}: needs at least 2 samples, has {t.size}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
            raise RbmError(f"{where}: times and accelerations must be finite")
        if t[0] < 0.0:
            raise RbmError(f"{where}: times must be >= 0 [s], got {t[0]!r}")
        steps = np.diff(t)
        if np.any(steps <= 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise RbmError(f"{where}: times must increase, t[{k + 1}] <= t[{k}]")
        t.setflags(write=False)
        a.setflags(write=False)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "acceleration", a)

    @classmethod
    def from_samples(
        cls, acceleration, dt: float, name: str = "record", source: str = "", title: str = ""
    ) -> Record:
        """A record sampled every ``dt`` [s] from t = 0; ``acceleration`` in [m/s^2]."""
        if not (np.isfinite(dt) and dt > 0.0):
            raise RbmError(f"record {name!r}: dt must be > 0 [s], got {dt!r}")
        a = np.asarray(acceleration, dtype=float).ravel()
        return cls(np.arange(a.size) * float(dt), a, name, source, title)

    @property
    def pga(self) -> float:
        """Peak ground acceleration max |a_g| [m/s^2]."""
        return float(np.max(np.abs(self.acceleration)))

    @property
    def duration(self) -> float:
        """Time of the last sample, from t = 0 [s]."""
        return float(self.t[-1])

    def __len__(self) -> int:
        return int(self.t.size)

    def at(self, t):
        """Ground acceleration a_g(t) [m/s^2]: linear between samples, 0 outside them.

        Parameters
        ----------
        t : float or array_like
            Times [s]

        Returns
        -------
        float or numpy.ndarray
            a_g at ``t`` [m/s^2] (a float for a scalar ``t``)
        """
        out = np.interp(t, self.t, self.acceleration, left=0.0, right=0.0)
        return float(out) if np.ndim(out) == 0 else out

    def scaled(self, factor: float) -> Record:
        """The record with its acceleration multiplied by ``factor`` [-]."""
        if not np.isfinite(factor):
            raise RbmError(f"record {self.name!r}: scale factor must be finite, got {factor!r}")
        return Record(self.t, self.acceleration * factor, self.name, self.source, self.title)

    def processed(self, processing: ProcessingConfig | None) -> Record:
        """The record processed as ``processing`` says (:func:`process`); itself for None."""
        if processing is None:
            return self
        values = process(self.t, self.acceleration, processing, self.name)
        return Record(self.t, values, self.name, self.source, self.title)


# --------------------------------------------------------------------------- processing


def displacement_at_samples(t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Displacement [m] at the sample times of the acceleration a [m/s^2], linear between
    its samples, integrated exactly from rest at the first sample (velocity by the
    trapezoid rule, displacement cubic between samples)."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    h = np.diff(t)
    v = np.concatenate([[0.0], np.cumsum(h * (a[:-1] + a[1:]) / 2.0)])
    return np.concatenate([[0.0], np.cumsum(v[:-1] * h + h * h * (2.0 * a[:-1] + a[1:]) / 6.0)])


def baseline_fit(t: np.ndarray, a: np.ndarray, degree: int) -> np.ndarray:
    """The polynomial in time of ``degree`` (its values at the samples [m/s^2]) whose
    removal from the acceleration a [m/s^2] leaves the least displacement: least squares
    on the displacement from rest (:func:`displacement_at_samples`), each sample weighted
    by the time it stands for (trapezoid weights, so uneven steps are fitted as the time
    integral of u^2). The displacement is linear in the acceleration, so the fit is that
    of the displacement of each power of time to the record's: the corrected record's own
    displacement is what is minimised. Time runs from the first sample, scaled by the
    record's length (the powers stay of order 1)."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    span = float(t[-1] - t[0])
    tau = (t - t[0]) / span
    powers = np.vstack([tau**j for j in range(degree + 1)]).T
    basis = np.column_stack([displacement_at_samples(t, powers[:, j]) for j in range(degree + 1)])
    h = np.diff(t)
    weight = np.sqrt(np.concatenate([[h[0]], h[:-1] + h[1:], [h[-1]]]) / 2.0)
    coef, *_ = np.linalg.lstsq(basis * weight[:, None], displacement_at_samples(t, a) * weight,
                               rcond=None)  # fmt: skip
    return powers @ coef


def remove_baseline(t: np.ndarray, a: np.ndarray, baseline: str) -> np.ndarray:
    """The acceleration a [m/s^2] less its baseline (:func:`baseline_fit`): ``none``
    (a as given), ``linear`` (a0 + a1 t) or ``quadratic`` (a0 + a1 t + a2 t^2)."""
    if baseline not in BASELINES:
        raise RbmError(f"baseline must be one of {', '.join(BASELINES)}, got {baseline!r}")
    a = np.asarray(a, dtype=float)
    degree = BASELINES.index(baseline)  # none 0 (nothing removed), linear 1, quadratic 2
    if degree == 0:
        return a.copy()
    return a - baseline_fit(t, a, degree)


def band_pass_sections(low_hz: float, high_hz: float, order: int, fs: float) -> np.ndarray:
    """Second-order sections of the band-pass: a Butterworth high-pass at low_hz and a
    low-pass at high_hz [Hz], each of ``order``, for samples at fs [Hz] (scipy.signal.butter,
    bilinear with the corners prewarped). One pass has the gain

    .. math:: |H(f)|^2 = \\frac{1}{1 + (\\tan(\\pi f_l / f_s) / \\tan(\\pi f / f_s))^{2n}}
              \\frac{1}{1 + (\\tan(\\pi f / f_s) / \\tan(\\pi f_h / f_s))^{2n}}

    (the analogue Butterworth's 1 / (1 + (f / f_c)^(2n)) a side, for f well below f_s)."""
    # lazy: scipy.signal loads only where needed (docs/architecture.md, Start-up)
    from scipy.signal import butter

    high = butter(order, low_hz, btype="highpass", fs=fs, output="sos")
    low = butter(order, high_hz, btype="lowpass", fs=fs, output="sos")
    return np.vstack([high, low])


def band_pass(t: np.ndarray, a: np.ndarray, low_hz: float, high_hz: float, order: int,
              name: str = "record") -> np.ndarray:  # fmt: skip
    """The acceleration a [m/s^2] band-passed between low_hz and high_hz [Hz], zero phase:
    :func:`band_pass_sections` run forward and backward (scipy.signal.sosfiltfilt, the
    record extended at each end by :func:`~rbm_cli.config.excitation.filter_padding`
    samples, odd about its end values), so its gain is |H(f)|^2 and its phase 0.

    Raises
    ------
    RbmError  Uneven time steps (a band-pass needs one step), 0 < low_hz < high_hz <
        the Nyquist frequency not met, or too few samples for the filter's padding.
    """
    # lazy: scipy.signal loads only where needed (docs/architecture.md, Start-up)
    from scipy.signal import sosfiltfilt

    where = f"record {name!r}"
    step = record_parsers.uniform_step(t)
    if step is None:
        raise RbmError(f"{where}: a band-pass needs even time steps: resample the record")
    fs = 1.0 / step
    if not 0.0 < low_hz < high_hz < 0.5 * fs:
        raise RbmError(
            f"{where}: a band-pass needs 0 < low_hz < high_hz < the Nyquist frequency"
            f" {0.5 * fs:g} Hz, got {low_hz:g} and {high_hz:g} Hz"
        )
    a = np.asarray(a, dtype=float)
    padding = filter_padding(order)
    if a.size <= padding:
        raise RbmError(f"{where}: a band-pass of order {order} needs more than {padding} samples")
    return sosfiltfilt(band_pass_sections(low_hz, high_hz, order, fs), a, padlen=padding)


def process(t: np.ndarray, a: np.ndarray, processing: ProcessingConfig | None,
            name: str = "record") -> np.ndarray:  # fmt: skip
    """A record's acceleration [m/s^2] at its sample times t [s], processed: band-passed
    (:func:`band_pass`) if ``processing.filter`` is given, then its baseline removed
    (:func:`remove_baseline`). The baseline comes last, as in the PEER NGA processing [2]_:
    fitted to the filtered record's displacement, it removes the drift a filter's ends can
    leave as well as the record's own. None: a copy of ``a``."""
    a = np.asarray(a, dtype=float)
    if processing is None:
        return a.copy()
    band = processing.filter
    if band is not None:
        a = band_pass(t, a, band.low_hz, band.high_hz, band.order, name)
    return remove_baseline(t, a, processing.baseline)


# --------------------------------------------------------------------------- reading


def read_record(path: str | os.PathLike, units: str = "g", fmt: str | None = None) -> Record:
    """Read a ground-motion record from a PEER NGA ``.AT2`` or a CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        The file; its suffix (``.at2`` or ``.csv``, any case) gives the format unless
        ``fmt`` is given
    units : str
        Units of a CSV's acceleration column: ``"g"`` (default) or ``"m/s2"``. An
        ``.AT2`` file is in g by definition; ``"m/s2"`` with one is refused.
    fmt : str, optional
        ``"at2"`` or ``"csv"``, to override the suffix

    Returns
    -------
    Record
        Times [s] and acceleration [m/s^2]; ``name`` is the file stem

    Raises
    ------
    RbmError
        On any malformed file, in one line naming the file and line: missing file,
        empty file, bad or missing header, NPTS not matching the number of values,
        DT <= 0, non-numeric or non-finite values, non-increasing or negative times,
        a CSV with fewer than 2 columns or 2 rows, unknown units, a file too large.

    Notes
    -----
    ``.AT2`` (PEER NGA): four header lines; the fourth gives the number of points and
    the time step, in either style in use::

        NPTS=  5000, DT=   .0050 SEC        (also NPTS= 5000 DT= 0.005)
        4096    0.0100    NPTS, DT          (older files)

    then the NPTS values in g, any number per line, Fortran exponents (``-.123E-02``,
    ``1.0D-02``) accepted. Sample k is at t = k DT.

    CSV: a header row of column names, then rows whose first column is the time [s] and
    second the acceleration (further columns ignored); time steps may be uneven. Blank
    lines and lines starting with ``#`` are skipped.

    Examples
    --------
    >>> rec = read_record("configs/records/synthetic/rdk_01.AT2")  # doctest: +SKIP
    >>> rec.pga / G  # doctest: +SKIP
    0.31
    """
    path = Path(path)
    t, values, title = record_parsers.read_file(path, units, fmt)
    return Record(t, values, path.stem, str(path), title)


# --------------------------------------------------------------------------- writing


def _uniform_dt(record: Record) -> float:
    n = len(record)
    dt = float(record.t[1] - record.t[0])
    expected = np.arange(n) * dt
    if record.t[0] != 0.0 or not np.allclose(record.t, expected, rtol=1e-9, atol=1e-12 * dt):
        raise RbmError(f"record {record.name!r}: an .AT2 file needs samples at t = k DT from t = 0")
    return dt


def write_at2(
    path: str | os.PathLike,
    record: Record | np.ndarray,
    *,
    dt: float | None = None,
    title: str | None = None,
    header_style: str = "new",
    values_per_line: int = 5,
) -> Path:
    """Write a record as a PEER NGA ``.AT2`` file (values in g, 8 significant digits).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (overwritten)
    record : Record or array_like
        A :class:`Record` sampled at t = k DT from 0, or the accelerations [m/s^2]
        (then ``dt`` is required)
    dt : float, optional
        Time step [s] for an array ``record``
    title : str, optional
        Header line 2 (default: the record's title or name)
    header_style : str
        ``"new"`` (``NPTS= n, DT= dt SEC``) or ``"old"`` (``n dt NPTS, DT``)
    values_per_line : int
        Values on each data line, >= 1

    Returns
    -------
    pathlib.Path
        The path written

    Examples
    --------
    >>> import numpy as np
    >>> a = 0.3 * G * np.sin(2 * np.pi * np.arange(101) * 0.01)
    >>> write_at2(tmp / "sine.AT2", a, dt=0.01)  # doctest: +SKIP
    """
    if not isinstance(record, Record):
        if dt is None:
            raise RbmError("write_at2: dt [s] is required with an array of accelerations")
        record = Record.from_samples(record, dt, name=Path(path).stem)
    step = _uniform_dt(record)
    if header_style not in ("new", "old"):
        raise RbmError(f"write_at2: header_style must be 'new' or 'old', got {header_style!r}")
    if values_per_line < 1:
        raise RbmError(f"write_at2: values_per_line must be >= 1, got {values_per_line}")
    n = len(record)
    head = title if title is not None else (record.title or record.name)
    if header_style == "new":
        line4 = f"NPTS= {n:7d}, DT= {step!r} SEC"
    else:
        line4 = f"{n:8d}   {step!r}   NPTS, DT"
    g_values = record.acceleration / G
    rows = [
        "".join(f"{v:15.7E}" for v in g_values[i : i + values_per_line])
        for i in range(0, n, values_per_line)
    ]
    lines = [
        "rbm ground-motion record (PEER NGA .AT2 format)",
        head.replace("\n", " "),
        "ACCELERATION TIME SERIES IN UNITS OF G",
        line4,
        *rows,
    ]
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8", newline="\n")
    return path


def write_csv(
    path: str | os.PathLike,
    record: Record | tuple[np.ndarray, np.ndarray],
    *,
    units: str = "g",
) -> Path:
    """Write a record as CSV: a header row, then time [s] and acceleration (17 digits).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (overwritten)
    record : Record or (t, acceleration)
        A :class:`Record`, or times [s] and accelerations [m/s^2]
    units : str
        Units of the written acceleration column: ``"g"`` or ``"m/s2"``

    Returns
    -------
    pathlib.Path
        The path written; :func:`read_record` with the same ``units`` reads it back
        exactly
    """
    if units not in _UNITS:
        raise RbmError(f"write_csv: units must be 'g' or 'm/s2', got {units!r}")
    if not isinstance(record, Record):
        t, a = record
        record = Record(t, a, name=Path(path).stem)
    column = "acceleration_g" if _UNITS[units] == G else "acceleration_m_s2"
    values = record.acceleration / _UNITS[units]
    body = "\n".join(
        f"{t!r},{v!r}" for t, v in zip(record.t.tolist(), values.tolist(), strict=True)
    )
    path = Path(path)
    path.write_text(f"time_s,{column}\n{body}\n", encoding="utf-8", newline="\n")
    return path
