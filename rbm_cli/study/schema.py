"""The schema of domain.csv: every column's name, dtype, unit and label, in the order the
writer writes them, and when a domain has it.

A domain's row is one cell of a sweep (rbm_cli.study.cells): its point's axes, the
sample of a config's uncertain keys (rbm_cli.config.uncertain: ``sample`` and one column
per key, ``uncertain.<key>``, the value the run used: :func:`point_columns`), then the
run's result (rbm_cli.study.result), the column's scales (rbm_cli.structures.similarity), a
record's intensity measures (their registry: rbm_cli.study.intensities) and an ensemble's
verdict (rbm_cli.study.robustness). :func:`columns` lists them (the measures as the
registry holds them when called); each :class:`Column` says
for which domains it is written (``when``: a function of the config and the ensemble's
size, and ``filled``, the same in words for the docs). The grid's axes over config keys
come first, one column per path, named by the path (dotted: the dots tell them from the
columns here); they are not in :data:`COLUMNS`, being the config's.

Everything that names a column reads it here: the writer (:func:`domain_columns`), the
reader's types (rbm_cli.study.domain), the
figures' axis labels (:func:`label`), the fragility's units (:func:`unit`), the docs'
table of columns (docs/_ext/rbm_reference.py, ``.. rbm-domain-columns::``). The names are
attributes of :data:`C` (``C.amplitude_g``), so a misspelt name fails where it is read.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

from rbm_cli.config.types import MODELS, Config
from rbm_cli.config.uncertain import PREFIX, SAMPLE
from rbm_cli.study import intensities
from rbm_cli.study.intensities import label as measure_label
from rbm_cli.study.intensities import measure_fields, measure_of

#: The dtypes of a column: a float (12 significant digits; empty: none), a whole number
#: (empty: none), 0/1, or text.
DTYPES = ("float", "int", "0/1", "str")
#: The groups of columns, in domain.csv's order.
GROUPS = ("sample", "record", "result", "scale", "measure", "ensemble")


def _always(config: Config, ensemble: int) -> bool:
    return True


def _records(config: Config, ensemble: int) -> bool:
    return config.excitation.type == "record"


def _three_d(config: Config, ensemble: int) -> bool:
    return bool(config.three_d)


def _friction_checked(config: Config, ensemble: int) -> bool:
    return bool(MODELS[config.model].beam and config.interface.friction_limit is not None)


def _residual(config: Config, ensemble: int) -> bool:
    return bool(MODELS[config.model].residual)


def _uncertain(config: Config, ensemble: int) -> bool:
    return config.uncertain is not None


def _ensemble(config: Config, ensemble: int) -> bool:
    return ensemble > 1


@dataclass(frozen=True)
class Column:
    """One column of domain.csv.

    name : str  Its header (its unit in it where it has one)
    dtype : str  One of :data:`DTYPES`
    unit : str  Its unit ("-": dimensionless, "": none, text or a count)
    quantity : str  What it holds, as a figure's axis names it (the label without the unit)
    group : str  One of :data:`GROUPS`
    filled : str  For which domains it is written, in words ("" for every domain)
    when : callable  (config, ensemble members) -> whether a domain has it
    """

    name: str
    dtype: str
    unit: str
    quantity: str
    group: str
    filled: str = ""
    when: Callable[[Config, int], bool] = _always

    def __post_init__(self) -> None:
        if self.dtype not in DTYPES or self.group not in GROUPS:
            raise ValueError(f"column {self.name}: dtype {self.dtype!r} must be one of"
                             f" {DTYPES}, group {self.group!r} of {GROUPS}")  # fmt: skip

    @property
    def label(self) -> str:
        """The axis label: quantity and unit (the quantity alone without a unit)."""
        return f"{self.quantity} [{self.unit}]" if self.unit else self.quantity


def _result(name, dtype, unit, quantity, filled="", when=_always) -> Column:
    return Column(name, dtype, unit, quantity, "result", filled, when)


def _scale(name, unit, quantity) -> Column:
    return Column(name, "float", unit, quantity, "scale")


_RECORD_ONLY = "record excitations (excitation.type: record)"
_RESIDUAL_ONLY = "model bullet; empty if it collapsed or failed"
_UNCERTAIN_ONLY = "configs with uncertain keys (the uncertain section)"
#: The name the schema gives the columns of the uncertain keys' values, one per key.
UNCERTAIN_PATTERN = PREFIX + "<key>"

#: domain.csv's columns after the grid's axes and before the record's measures, in order.
_BEFORE: tuple[Column, ...] = (
    Column(
        SAMPLE,
        "int",
        "",
        "sample of the uncertain keys (0, 1, ...; a row per cell and sample)",
        "sample",
        _UNCERTAIN_ONLY,
        _uncertain,
    ),  # fmt: skip
    Column(
        UNCERTAIN_PATTERN,
        "float",
        "",
        "the value of an uncertain key the sample's run used (the key's unit in the config)",
        "sample",
        _UNCERTAIN_ONLY + ": one column per key, uncertain.<dotted key>",
        _uncertain,
    ),  # fmt: skip
    Column(
        "record", "str", "", "record", "record", _RECORD_ONLY + ": the record's name", _records
    ),  # fmt: skip
    _result("amplitude_g", "float", "g", "amplitude"),
    _result("frequency_hz", "float", "Hz", "frequency", "empty for records"),
    _result(
        "status",
        "str",
        "",
        "outcome: collapsed, survived or failed (a run that failed"
        " numerically, with its message; the sweep goes on)",
    ),  # fmt: skip
    _result("collapsed", "0/1", "", "collapsed"),
    _result("t_collapse_s", "float", "s", "time of collapse", "empty without one"),
    _result(
        "collapse_interface",
        "int",
        "",
        "interface that reached its limit (1 at the ground; a frame's beam joint: n + 1)",
        "empty without a collapse",
    ),  # fmt: skip
    _result(
        "max_rotation_ratio",
        "float",
        "-",
        "peak rotation ratio (collapse quantity / limit)",
        "1 at collapse",
    ),  # fmt: skip
    _result("max_top_displacement_m", "float", "m", "peak top displacement |u_top - u_base|"),
    _result(
        "collapse_azimuth_deg",
        "float",
        "deg",
        "azimuth of the lean at collapse, from x",
        "models in three dimensions; empty if it survived",
        _three_d,
    ),  # fmt: skip
    _result(
        "wobble_turns",
        "float",
        "turns",
        "angle the lean's direction swept while it rolled",
        "models in three dimensions",
        _three_d,
    ),  # fmt: skip
    _result(
        "residual_slip_m",
        "float",
        "m",
        "residual slip: the largest |slip| of a joint where the run ended",
        _RESIDUAL_ONLY,
        _residual,
    ),  # fmt: skip
    _result(
        "residual_top_offset_m",
        "float",
        "m",
        "residual top offset: the top's offset in plan from its start where the run ended",
        _RESIDUAL_ONLY,
        _residual,
    ),  # fmt: skip
    _result(
        "residual_tilt_ratio",
        "float",
        "-",
        "residual tilt: the largest |relative rotation| / alpha_i of a joint where the run ended",
        _RESIDUAL_ONLY,
        _residual,
    ),  # fmt: skip
    _result("n_uplifts", "int", "", "uplifts"),
    _result("n_impacts", "int", "", "impacts"),
    _result("n_steps", "int", "", "integrator steps"),
    _result("n_rhs", "int", "", "right-hand-side evaluations"),
    _result(
        "friction_demand",
        "float",
        "-",
        "friction demand: the largest |T_i/N_i| over the joints held in one direction for 0.03 s",
        "models rbm and rbm-3d; empty for the others",
    ),  # fmt: skip
    _result(
        "slides",
        "0/1",
        "",
        "friction_demand above interface.friction",
        "models rbm and rbm-3d with interface.friction",
        _friction_checked,
    ),  # fmt: skip
    _result("message", "str", "", "the integrator's message"),
    _scale("alpha_rad", "rad", "slenderness alpha (tan alpha: the uplift level in g)"),
    _scale("p_rad_s", "rad/s", "frequency parameter p"),
    _scale("static_multiplier", "g", "static multiplier"),
    _scale("a_over_g_alpha", "-", r"$A / (g \tan\alpha)$"),
    _scale("omega_over_p", "-", r"$\omega / p$"),
)
#: domain.csv's last columns, after the record's measures.
_AFTER: tuple[Column, ...] = (
    Column(
        "collapse_fraction",
        "float",
        "-",
        "fraction of ensemble members that collapsed",
        "ensemble",
        "ensembles (rbm sweep --ensemble K)",
        _ensemble,
    ),  # fmt: skip
    Column(
        "robust",
        "0/1",
        "",
        "robust: all members agree, none failed and the solver check gives member 0's outcome",
        "ensemble",
        "ensembles (rbm sweep --ensemble K)",
        _ensemble,
    ),  # fmt: skip
    Column(
        "sensitive_to",
        "str",
        "",
        "why a cell is not robust: inputs, solver or both (none: robust)",
        "ensemble",
        "ensembles (rbm sweep --ensemble K)",
        _ensemble,
    ),  # fmt: skip
)


def measure_columns() -> tuple[Column, ...]:
    """The columns of the registry's measures (rbm_cli.study.intensities.MEASURES, read
    now), in its order (a measure per period as its pattern, ``sa_<T>s_g``)."""
    return tuple(
        Column(m.column, "float", m.unit, m.quantity, "measure", _RECORD_ONLY, _records)
        for m in intensities.MEASURES
    )


def columns() -> tuple[Column, ...]:
    """domain.csv's columns after the grid's axes, in order (module docstring), with the
    registry's measures as it is now."""
    return _BEFORE + measure_columns() + _AFTER


#: The columns, in order, with the registry's measures as imported (:func:`columns` reads
#: the registry when called).
COLUMNS: tuple[Column, ...] = columns()
#: The names as attributes: ``C.amplitude_g == "amplitude_g"`` (a measure per period has
#: none: :func:`rbm_cli.study.intensities.sa_field`).
C = SimpleNamespace(**{c.name: c.name for c in COLUMNS if c.name.isidentifier()})
#: The columns a fragility takes for its intensity when none is named, the first present:
#: the amplitude, under the names a table of another program may give it too.
DEFAULT_INTENSITIES = ("intensity_g", C.amplitude_g, "intensity")
#: The columns of each group, by name, in order.
RESULT_COLUMNS = tuple(c.name for c in COLUMNS if c.group == "result")
#: The result's columns every domain has (the others depend on the model and the config).
COMMON_RESULT_COLUMNS = tuple(c.name for c in COLUMNS if c.group == "result" and c.when is _always)
SCALE_COLUMNS = tuple(c.name for c in COLUMNS if c.group == "scale")
#: The result's columns of a model whose drums may slide for good (MODELS' ``residual``:
#: the contact engine): the residual slip [m], top offset [m] and tilt ratio [-].
RESIDUAL_COLUMNS = tuple(c.name for c in COLUMNS if c.when is _residual)
ENSEMBLE_COLUMNS = tuple(c.name for c in COLUMNS if c.group == "ensemble")


def column(name: str) -> Column | None:
    """The schema's entry of a column (``sa_0p5s_g``: the measure per period's), None for
    another (an axis's path, a column of an older rbm)."""
    measure = measure_of(name)
    if measure is not None:
        name = measure.column
    elif str(name).startswith(PREFIX):
        name = UNCERTAIN_PATTERN
    return next((c for c in columns() if c.name == name), None)


def label(name: str) -> str | None:
    """The axis label of a column (quantity and unit), None for one not in the schema."""
    if measure_of(name) is not None:
        return measure_label(name)
    entry = column(name)
    return None if entry is None else entry.label


def unit(name: str) -> str | None:
    """The unit of a column, None for one not in the schema."""
    entry = column(name)
    return None if entry is None else entry.unit


def point_columns(config: Config) -> tuple[str, ...]:
    """The columns that tell a row's point (rbm_cli.config.points): the grid's axis paths,
    then a sample's (``sample``, ``uncertain.<key>`` per key) where the config has
    uncertain keys. With amplitude and frequency they are a row's identity."""
    sample = () if config.uncertain is None else config.uncertain.columns
    return (*config.grid.axis_paths, *sample)


def domain_columns(config: Config, ensemble: int = 1, result=None) -> tuple[str, ...]:
    """domain.csv's columns for a sweep of ``config`` with ``ensemble`` runs per cell, in
    order: the axis paths, then :data:`COLUMNS` that this domain has (a measure per period
    once per period of excitation.im_periods, an uncertain key's value once per key).
    ``result``: the result's columns to keep (None: all; the columns that depend on the
    model are kept where the domain has them)."""
    keep = None if result is None else set(result)
    out = list(config.grid.axis_paths)
    measures = measure_fields(config)
    for entry in columns():
        if not entry.when(config, ensemble):
            continue
        if entry.group == "sample":
            out.extend(c for c in config.uncertain.columns if column(c) is entry)
        elif entry.group == "measure":
            out.extend(m for m in measures if measure_of(m).column == entry.name)
        elif keep is not None and entry.name in COMMON_RESULT_COLUMNS and entry.name not in keep:
            continue
        else:
            out.append(entry.name)
    return tuple(out)


def scale_values(scales, amplitude_g: float, frequency_hz: float | None) -> dict:
    """The scale columns of one cell (:data:`SCALE_COLUMNS`), as domain.csv holds them
    (rbm_cli.structures.similarity.RockingScales)."""
    a_ratio, w_ratio = scales.dimensionless(amplitude_g, frequency_hz)
    values = (scales.alpha, scales.p, scales.static_multiplier, a_ratio, w_ratio)
    return dict(zip(SCALE_COLUMNS, values, strict=True))


__all__ = [
    "COLUMNS",
    "DTYPES",
    "ENSEMBLE_COLUMNS",
    "GROUPS",
    "RESIDUAL_COLUMNS",
    "RESULT_COLUMNS",
    "SCALE_COLUMNS",
    "COMMON_RESULT_COLUMNS",
    "DEFAULT_INTENSITIES",
    "UNCERTAIN_PATTERN",
    "C",
    "Column",
    "column",
    "columns",
    "domain_columns",
    "label",
    "measure_columns",
    "point_columns",
    "scale_values",
    "unit",
]
