"""The registry of intensity measures: what a record cell's row in domain.csv holds of its
record, one entry per measure (:data:`MEASURES`).

A row of a record excitation carries the measures of the record as run (scaled, and
processed when ``excitation.processing`` asks), each column named with its unit. An entry
(:class:`IntensityMeasure`) says everything the rest of rbm reads of a measure:

- ``column``: its domain.csv column (for a measure per period, the pattern
  ``sa_<T>s_g``: one column per period, :func:`sa_field`);
- ``quantity`` and ``unit``: how a figure's axis and the docs name it;
- ``compute(t, a, period_s)``: its value [SI] for the record as read (times [s],
  accelerations [m/s^2]; ``period_s`` the entry's period, None for a measure without
  one), a function of rbm_cli.inputs.intensity;
- ``scaling``: how it goes with the factor c a cell multiplies the record by, in
  :data:`SCALINGS`: ``linear`` (|c|: PGA, PGV, PGD, CAV, Sa), ``quadratic`` (c^2: Arias
  intensity) or ``none`` (D5-95, the column's period); a measure that grows with the
  scale is an intensity a fragility may be fitted on (:func:`fragility_measures`);
- ``express(value, column)``: the scaled value [SI] in the column's unit (the column's
  scales and period in ``column``: :class:`ColumnContext`);
- ``period``: None, ``t1`` (at the column's first elastic period: empty for a rigid
  column) or ``im_periods`` (one column per period of ``excitation.im_periods``).

The measures, in domain.csv's order:

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
  PGV p / (g tan alpha) [-], alpha and p the column's scales (rbm_cli.structures.similarity).

Measures are computed once per record (and per process: a worker keeps them for every
chunk of that record it runs) and scaled to each cell: the record is multiplied by
amplitude / its PGA (``excitation.scale: pga``) or by the amplitude (``factor``). Rows of
other excitations have none of these columns. The vertical record, if any, is not
measured: these are the horizontal record's. A pair of records (``excitation.file_y``) is
scaled by one factor (the larger of its two PGAs to the amplitude, with ``scale: pga``),
and each of its measures is the larger of its two components' (the longer D5-95): its
``pga_g`` is then the amplitude.

Adding a measure is one entry in :data:`MEASURES` (docs/architecture.md): domain.csv's
columns (rbm_cli.study.schema), the fragility's choices, the figures' labels and the
docs' table of columns read it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import MODELS, Config, G
from rbm_cli.inputs import intensity as im
from rbm_cli.inputs.excitation import load_record
from rbm_cli.inputs.records import process
from rbm_cli.structures.assembly import model_from_config

#: How a measure goes with the factor c a cell multiplies its record by.
SCALINGS = ("linear", "quadratic", "none")
#: Where a measure is taken: no period, the column's first elastic period, or each period
#: of excitation.im_periods.
PERIODS = (None, "t1", "im_periods")


@dataclass(frozen=True)
class ColumnContext:
    """What a measure's column value may read of the column: tan alpha [-] and p [rad/s]
    (rbm_cli.structures.similarity), and the first elastic period t1 [s] (None: rigid)."""

    tan_alpha: float
    p: float
    t1_s: float | None


def _as_is(value: float, column: ColumnContext) -> float:
    return value


def _in_g(value: float, column: ColumnContext) -> float:
    return value / G


@dataclass(frozen=True)
class IntensityMeasure:
    """One intensity measure of a record (module docstring)."""

    column: str
    quantity: str
    unit: str
    compute: Callable[..., float]
    scaling: str = "linear"
    express: Callable[[float, ColumnContext], float] = _as_is
    period: str | None = None

    def __post_init__(self) -> None:
        if self.scaling not in SCALINGS or self.period not in PERIODS:
            raise ValueError(
                f"intensity measure {self.column}: scaling {self.scaling!r} must be one of"
                f" {SCALINGS}, period {self.period!r} one of {PERIODS}"
            )

    @property
    def label(self) -> str:
        """The axis label of its column: quantity and unit."""
        return f"{self.quantity} [{self.unit}]"

    def scaled(self, value: float, factor: float) -> float:
        """``value`` [SI] of the record as read, for the record times ``factor``."""
        c = abs(float(factor))
        if self.scaling == "linear":
            return c * value
        if self.scaling == "quadratic":
            return c * c * value
        return value


def _of_record(measure):
    """A measure of the record alone (times, accelerations), as the registry calls it."""

    def compute(t, a, period_s=None) -> float:
        return measure(t, a)

    return compute


_pga = _of_record(im.peak_acceleration)
_pgv = _of_record(im.peak_velocity)


def _sa(t, a, period_s) -> float:
    return im.spectral_acceleration(t, a, float(period_s), im.DAMPING)


def _period(t, a, period_s) -> float:
    return period_s


def _over_g_tan_alpha(value: float, column: ColumnContext) -> float:
    return value / (G * column.tan_alpha)


def _p_over_g_tan_alpha(value: float, column: ColumnContext) -> float:
    return value * column.p / (G * column.tan_alpha)


#: The registry, in domain.csv's order (module docstring).
MEASURES: tuple[IntensityMeasure, ...] = (
    IntensityMeasure("pga_g", "peak ground acceleration PGA", "g", _pga, express=_in_g),
    IntensityMeasure("pgv_m_s", "peak ground velocity PGV", "m/s", _pgv),
    IntensityMeasure(
        "pgd_m",
        "peak ground displacement PGD",
        "m",
        _of_record(im.peak_displacement),
    ),  # fmt: skip
    IntensityMeasure(
        "arias_m_s",
        "Arias intensity",
        "m/s",
        _of_record(im.arias_intensity),
        scaling="quadratic",
    ),  # fmt: skip
    IntensityMeasure(
        "cav_m_s",
        "cumulative absolute velocity CAV",
        "m/s",
        _of_record(im.cumulative_absolute_velocity),
    ),  # fmt: skip
    IntensityMeasure(
        "d5_95_s",
        "significant duration D5-95",
        "s",
        _of_record(im.significant_duration),
        scaling="none",
    ),  # fmt: skip
    IntensityMeasure(
        "t1_s", "the column's first elastic period T1", "s", _period, scaling="none", period="t1"
    ),  # fmt: skip
    IntensityMeasure(
        "sa_t1_g",
        "Sa(T1, 5 %) at the column's first elastic period",
        "g",
        _sa,
        express=_in_g,
        period="t1",
    ),  # fmt: skip
    IntensityMeasure(
        "sa_<T>s_g",
        "Sa(T, 5 %) at each period T of excitation.im_periods",
        "g",
        _sa,
        express=_in_g,
        period="im_periods",
    ),  # fmt: skip
    IntensityMeasure(
        "pga_over_g_tan_alpha", "PGA / (g tan alpha)", "-", _pga, express=_over_g_tan_alpha
    ),  # fmt: skip
    IntensityMeasure(
        "pgv_p_over_g_tan_alpha", "PGV p / (g tan alpha)", "-", _pgv, express=_p_over_g_tan_alpha
    ),  # fmt: skip
)


def sa_field(period_s: float) -> str:
    """The column of Sa at a period [s]: ``sa_<T>s_g``, its decimal point written ``p``."""
    return f"sa_{float(period_s):g}s_g".replace(".", "p").replace("+", "")


def _period_of(column: str) -> float | None:
    """The period [s] of a column written as :func:`sa_field` writes it, else None."""
    if not (column.startswith("sa_") and column.endswith("s_g")):
        return None
    try:
        period = float(column[3:-3].replace("p", "."))
    except ValueError:
        return None
    return period if period > 0.0 and sa_field(period) == column else None


def measure_of(column: str) -> IntensityMeasure | None:
    """The registry's entry of a domain.csv column (``sa_0p5s_g``: the entry per period),
    None for a column that is not a measure's."""
    for measure in MEASURES:
        if measure.period == "im_periods":
            if _period_of(column) is not None:
                return measure
        elif measure.column == column:
            return measure
    return None


def label(column: str) -> str | None:
    """The axis label of a measure's column (quantity and unit), None for another column."""
    measure = measure_of(column)
    if measure is None:
        return None
    if measure.period == "im_periods":
        return f"Sa({column[3:-3].replace('p', '.')} s, 5 %) [{measure.unit}]"
    return measure.label


def fragility_measures() -> tuple[IntensityMeasure, ...]:
    """The measures a fragility may be fitted on: those that grow with the record's scale."""
    return tuple(m for m in MEASURES if m.scaling != "none")


def _columns(config: Config) -> list[tuple[IntensityMeasure, str, object]]:
    """(entry, column, period) of each measure column of a record config's rows, in order;
    the period: None, "t1", or a period [s] of excitation.im_periods."""
    out = []
    for measure in MEASURES:
        if measure.period == "im_periods":
            out.extend((measure, sa_field(p), float(p)) for p in config.excitation.im_periods)
        else:
            out.append((measure, measure.column, measure.period))
    return out


def measure_fields(config: Config) -> tuple[str, ...]:
    """The measure columns of a record config's rows (module docstring), () otherwise."""
    if config.excitation.type != "record":
        return ()
    return tuple(column for _, column, _ in _columns(config))


def column_period(config: Config) -> float | None:
    """The column's first elastic period [s], None for a rigid one (module docstring)."""
    if not MODELS[config.model].beam:
        return None
    model = model_from_config(config)
    if model.rigid:
        return None
    slopes = np.array([law.slopes[0] for law in model.laws])
    stiffness = model.arg_map.T @ np.diag(slopes) @ model.arg_map - model.gravity
    return im.first_elastic_period(model.mass, stiffness)


def _record(config: Config, second: bool = False):
    """(times [s], accelerations [m/s^2]) of a record config's record (its second
    horizontal component, ``excitation.file_y`` or a motion's ``acceleration_y``, if
    second), as the run reads it:
    processed as ``excitation.processing`` says (rbm_cli.inputs.records.process)."""
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


#: The values [SI] of each record met in this process, by (record identity, t1, the
#: measure columns asked for).
_MEASURED: dict = {}


def record_values(config: Config, t1: float | None, second: bool = False) -> dict:
    """{column: value [SI]} of a record config's record (its second horizontal component
    if second) as read (unscaled), the record's PGA [m/s^2] under ``None``: its measures at
    the column's period t1 (nan without one) and at excitation.im_periods; once per record
    and process."""
    exc = config.excitation
    if second:
        identity = (str(exc.file_y_path or exc.file_y), exc.units, exc.file_y_sha256,
                    exc.processing)  # fmt: skip
    else:
        identity = (str(exc.file_path or exc.file), exc.units, exc.file_sha256, exc.processing)
    key = (identity, t1, measure_fields(config))
    if key not in _MEASURED:
        t, a = _record(config, second)
        t, a = np.asarray(t, float), np.asarray(a, float)
        values = {None: im.peak_acceleration(t, a)}
        for measure, column, period in _columns(config):
            if period == "t1":
                values[column] = math.nan if t1 is None else measure.compute(t, a, t1)
            else:
                values[column] = measure.compute(t, a, period)
        _MEASURED[key] = values
    return _MEASURED[key]


def scale_factor(config: Config, amplitude_g: float, pga: float) -> float:
    """The factor a cell multiplies its record by (as rbm_cli.inputs.excitation does):
    amplitude / PGA with ``scale: pga``, the amplitude with ``factor``."""
    if config.excitation.scale == "pga":
        return amplitude_g * G / pga
    return float(amplitude_g)


def measure_values(config: Config, amplitude_g: float, scales, t1: float | None) -> dict:
    """The measure columns of one cell's row, each in its entry's unit."""
    values = record_values(config, t1)
    if config.excitation.file_y is not None:  # a pair: scaled as one, the larger of each
        other = record_values(config, t1, second=True)
        values = {k: max(v, other[k]) for k, v in values.items()}
    factor = scale_factor(config, amplitude_g, values[None])
    column = ColumnContext(math.tan(scales.alpha), scales.p, t1)
    out = {}
    for measure, name, _ in _columns(config):
        value = values[name]
        out[name] = math.nan if math.isnan(value) else measure.express(
            measure.scaled(value, factor), column)  # fmt: skip
    return out


__all__ = [
    "MEASURES",
    "PERIODS",
    "SCALINGS",
    "ColumnContext",
    "IntensityMeasure",
    "column_period",
    "fragility_measures",
    "label",
    "measure_fields",
    "measure_of",
    "measure_values",
    "record_values",
    "sa_field",
    "scale_factor",
]
