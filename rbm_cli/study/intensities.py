"""The intensity measures of a record cell's row in domain.csv (rbm_cli.physics.intensity).

A row of a record excitation carries the measures of the record as run (scaled, and
processed when ``excitation.processing`` asks), each column named with its unit:

- ``pga_g``, ``pgv_m_s``, ``pgd_m``, ``arias_m_s``, ``cav_m_s``, ``d5_95_s``;
- ``t1_s``: the column's first elastic period, and ``sa_t1_g``: the 5 %-damped spectral
  acceleration there. Only a column that deforms before it rocks has one: the RBM with
  elastic interfaces, whose period is that of M theta'' + K theta = 0 on the first
  (elastic) branch of every interface's law. A rigid column (rigid interfaces, or the
  rigid-block models housner, housner-linear and bullet) has none: both are empty;
- ``sa_<T>s_g`` at each period T [s] of ``excitation.im_periods``, the period written
  with ``p`` for its decimal point (``sa_0p5s_g``: 0.5 s; a domain's dotted columns are
  its axes);
- ``pga_over_g_tan_alpha`` = PGA / (g tan alpha) and ``pgv_p_over_g_tan_alpha`` =
  PGV p / (g tan alpha) [-], alpha and p the column's scales (rbm_cli.physics.similarity).

Measures are computed once per record (and per process: a worker keeps them for every
chunk of that record it runs) and scaled to each cell: the record is multiplied by
amplitude / its PGA (``excitation.scale: pga``) or by the amplitude (``factor``), so PGA,
PGV, PGD, CAV and Sa scale linearly, Arias intensity as the square, D5-95 not at all.
Rows of other excitations have none of these columns (domain.csv is as before). The
vertical record, if any, is not measured: these are the horizontal record's. A pair of
records (``excitation.file_y``) is scaled by one factor (the larger of its two PGAs to the
amplitude, with ``scale: pga``), and each of its measures is the larger of its two
components' (the longer D5-95): its ``pga_g`` is then the amplitude.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.config.types import MODELS, Config, G
from rbm_cli.physics.intensity import RecordMeasures, first_elastic_period, record_measures

#: The measures every record row has, before the spectral accelerations at im_periods.
BASE_FIELDS = ("pga_g", "pgv_m_s", "pgd_m", "arias_m_s", "cav_m_s", "d5_95_s", "t1_s",
               "sa_t1_g")  # fmt: skip
#: The dimensionless rocking measures, last.
ROCKING_FIELDS = ("pga_over_g_tan_alpha", "pgv_p_over_g_tan_alpha")
#: The measure, its quantity and unit, as a figure's axis names it.
LABELS = {
    "pga_g": "peak ground acceleration PGA [g]",
    "pgv_m_s": "peak ground velocity PGV [m/s]",
    "pgd_m": "peak ground displacement PGD [m]",
    "arias_m_s": "Arias intensity [m/s]",
    "cav_m_s": "cumulative absolute velocity CAV [m/s]",
    "d5_95_s": "significant duration D5-95 [s]",
    "sa_t1_g": "Sa(T1, 5 %) at the column's first elastic period [g]",
    "pga_over_g_tan_alpha": "PGA / (g tan alpha) [-]",
    "pgv_p_over_g_tan_alpha": "PGV p / (g tan alpha) [-]",
}


def sa_field(period_s: float) -> str:
    """The column of Sa at a period [s]: ``sa_<T>s_g``, its decimal point written ``p``."""
    return f"sa_{float(period_s):g}s_g".replace(".", "p").replace("+", "")


def label(column: str) -> str | None:
    """The axis label of a measure's column (quantity and unit), None for another column."""
    if column in LABELS:
        return LABELS[column]
    if column.startswith("sa_") and column.endswith("s_g"):
        period = column[3:-3].replace("p", ".")
        return f"Sa({period} s, 5 %) [g]"
    return None


def measure_fields(config: Config) -> tuple[str, ...]:
    """The measure columns of a record config's rows (module docstring), () otherwise."""
    if config.excitation.type != "record":
        return ()
    return BASE_FIELDS + tuple(sa_field(p) for p in config.excitation.im_periods) + ROCKING_FIELDS


def column_period(config: Config) -> float | None:
    """The column's first elastic period [s], None for a rigid one (module docstring)."""
    if not MODELS[config.model].beam:
        return None
    from rbm_cli.physics.assembly import model_from_config

    model = model_from_config(config)
    if model.rigid:
        return None
    slopes = np.array([law.slopes[0] for law in model.laws])
    stiffness = model.arg_map.T @ np.diag(slopes) @ model.arg_map - model.gravity
    return first_elastic_period(model.mass, stiffness)


def _record(config: Config, second: bool = False):
    """(times [s], accelerations [m/s^2]) of a record config's record (its second
    horizontal component, ``excitation.file_y`` or a motion's ``acceleration_y``, if
    second), as the run reads it:
    processed as ``excitation.processing`` says (rbm_cli.physics.records.process)."""
    from rbm_cli.physics.excitation import load_record
    from rbm_cli.physics.records import process

    exc = config.excitation
    if exc.motion is not None:  # given as arrays (a pair: its y component if second)
        t, name = exc.motion.time_s, exc.motion.name
        a = exc.motion.acceleration_y_m_s2 if second else exc.motion.acceleration_m_s2
    elif second:
        rec = load_record(str(exc.file_y_path or exc.file_y), exc.units, exc.file_y_sha256)
        t, a, name = rec.t, rec.acceleration, rec.name
    else:
        rec = load_record(str(exc.file_path or exc.file), exc.units, exc.file_sha256)
        t, a, name = rec.t, rec.acceleration, rec.name
    t, a = np.asarray(t, float), np.asarray(a, float)
    if exc.processing is None:
        return t, a
    return t, np.asarray(process(t, a, exc.processing, name), float)


#: The measures of each record met in this process, by (record identity, periods).
_MEASURED: dict = {}


def record_measures_of(config: Config, t1: float | None, second: bool = False) -> RecordMeasures:
    """The measures of a record config's record (its second horizontal component if
    second) as read (unscaled), at the periods t1 (if any) and excitation.im_periods; once
    per record and process."""
    exc = config.excitation
    if second:
        identity = (str(exc.file_y_path or exc.file_y), exc.units, exc.file_y_sha256,
                    exc.processing)  # fmt: skip
    else:
        identity = (str(exc.file_path or exc.file), exc.units, exc.file_sha256, exc.processing)
    periods = ((t1,) if t1 is not None else ()) + tuple(exc.im_periods)
    key = (identity, periods)
    if key not in _MEASURED:
        _MEASURED[key] = record_measures(*_record(config, second), periods)
    return _MEASURED[key]


def _larger(a: RecordMeasures, b: RecordMeasures) -> RecordMeasures:
    """A pair's measures: each the larger of its two components' (the longer D5-95)."""
    return RecordMeasures(
        pga=max(a.pga, b.pga), pgv=max(a.pgv, b.pgv), pgd=max(a.pgd, b.pgd),
        arias=max(a.arias, b.arias), cav=max(a.cav, b.cav), d5_95=max(a.d5_95, b.d5_95),
        sa={period: max(value, b.sa[period]) for period, value in a.sa.items()},
    )  # fmt: skip


def scale_factor(config: Config, amplitude_g: float, pga: float) -> float:
    """The factor a cell multiplies its record by (as rbm_cli.physics.excitation does):
    amplitude / PGA with ``scale: pga``, the amplitude with ``factor``."""
    if config.excitation.scale == "pga":
        return amplitude_g * G / pga
    return float(amplitude_g)


def measure_values(config: Config, amplitude_g: float, scales, t1: float | None) -> dict:
    """The measure columns of one cell's row (g, m, s in the names' units)."""
    unit = record_measures_of(config, t1)
    if config.excitation.file_y is not None:  # a pair: scaled as one, the larger of each
        unit = _larger(unit, record_measures_of(config, t1, second=True))
    m = unit.scaled(scale_factor(config, amplitude_g, unit.pga))
    tan_alpha = math.tan(scales.alpha)
    out = {
        "pga_g": m.pga / G,
        "pgv_m_s": m.pgv,
        "pgd_m": m.pgd,
        "arias_m_s": m.arias,
        "cav_m_s": m.cav,
        "d5_95_s": m.d5_95,
        "t1_s": t1 if t1 is not None else math.nan,
        "sa_t1_g": m.sa[t1] / G if t1 is not None else math.nan,
    }
    out.update({sa_field(p): m.sa[float(p)] / G for p in config.excitation.im_periods})
    out["pga_over_g_tan_alpha"] = m.pga / (G * tan_alpha)
    out["pgv_p_over_g_tan_alpha"] = m.pgv * scales.p / (G * tan_alpha)
    return out


__all__ = [
    "BASE_FIELDS",
    "LABELS",
    "ROCKING_FIELDS",
    "column_period",
    "label",
    "measure_fields",
    "measure_values",
    "record_measures_of",
    "sa_field",
    "scale_factor",
]
