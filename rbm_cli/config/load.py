"""Read a YAML config into the validated, frozen dataclasses of :mod:`rbm_cli.config.types`.

Every user error raises :class:`rbm_cli.base.errors.ConfigError` with one line that names
the YAML key path and the allowed range or values, e.g.
``cfg.yaml: column.height must be a number > 0 [m], got -1``.

The schema is the column, interface, excitation (with ``excitation.initial``), grid and
``solver`` (integrator settings) sections; every key with its unit, default and range is in
the site's configuration reference (docs/reference/config.md), generated from this module.
Lengths are in m, stiffnesses in N m/rad (K_M) or Pa/m (k_n), times in s, angles in rad;
the grid keeps amplitudes in g and frequencies in Hz, the edge units.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.excitation import excitation_section
from rbm_cli.config.grid import (
    AMPLITUDE_RANGE_G,
    FREQUENCY_RANGE_HZ,
    MAX_POINTS,
    RECORD_PATHS,
    hoist_suite,
    parse_grid,
)
from rbm_cli.config.interface import interface_section
from rbm_cli.config.points import expand, point_written
from rbm_cli.config.types import (
    IMPLEMENTATIONS,
    METHODS,
    MODELS,
    SECTIONS,
    STOPS,
    CapitalConfig,
    CollapseConfig,
    ColumnConfig,
    Config,
    FrameConfig,
    SolverConfig,
    TopMassConfig,
)
from rbm_cli.config.uncertain import parse_uncertain, probe_values, with_design
from rbm_cli.config.validate import (
    choice,
    describe,
    fmt,
    in_bounds,
    integer,
    is_number,
    join,
    mapping,
    number,
    number_list,
    one_line,
)
from rbm_cli.config.written import plain_copy
from rbm_cli.config.yaml_reader import read_yaml

__all__ = [
    "AMPLITUDE_RANGE_G",
    "FREQUENCY_RANGE_HZ",
    "check_cell",
    "load_config",
    "parse_config",
]

TOP_KEYS = (
    "name", "model", "column", "interface", "excitation", "grid", "collapse", "solver",
    "uncertain", "frame",
)  # fmt: skip
COLUMN_KEYS = (
    "height",
    "base_width",
    "top_width",
    "section",
    "depth",
    "density",
    "drums",
    "capital",
    "top_mass",
)
CAPITAL_KEYS = ("height", "width", "depth")
TOP_MASS_KEYS = ("mass", "height_of_centre")
FRAME_KEYS = ("columns", "beam_mass")
#: Columns of a frame the tool accepts: a bay of two to a long colonnade.
MAX_FRAME_COLUMNS = 1000
#: Beam masses the tool accepts [kg] [assumption]: up to many times the heaviest stone
#: entablature; far beyond, the beam's share swamps a column's own mass in floating point.
BEAM_MASS_RANGE = (0.0, 1e12)
#: Masses of a top mass the tool accepts [kg] [assumption]: a laboratory weight to the
#: share of a heavy stone entablature many times a column's own mass.
TOP_MASS_RANGE = (1e-3, 1e9)
COLLAPSE_KEYS = ("ratio",)
SOLVER_KEYS = (
    "method",
    "rtol",
    "atol",
    "max_steps",
    "max_events",
    "time_step",
    "implementation",
    "max_wall_time",
    "stop",
)

#: Models of the config's ``model`` key that this version does not implement yet.
PLANNED_MODELS: tuple[str, ...] = ()
#: Models that accept any number of drums (the reference blocks are monolithic).
MULTI_DRUM_MODELS = tuple(name for name, entry in MODELS.items() if entry.multi_drum)
#: Range of solver.time_step, the contact engine's fixed step [s].
TIME_STEP_RANGE = (1e-6, 1e-2)
MAX_DRUMS = 200
MAX_TOP_TAPER = 3.0  # top_width <= MAX_TOP_TAPER * base_width (and <= height)
#: Heights of a column or block the tool accepts [m] [assumption]: a laboratory
#: block to a tower; far outside, masses and inertias overflow or underflow.
HEIGHT_RANGE = (1e-3, 1e3)
#: Widths, depth and drum heights [m] and density [kg/m^3] the tool accepts [assumption]:
#: wide enough for any stone column or laboratory model, narrow enough that masses,
#: inertias and moments stay far inside floating point (density 1e307 overflowed them
#: and reported a collapsing column as survived).
LENGTH_RANGE = (1e-4, 1e3)
#: Height, width and depth of a capital [m]. Below 0.1 m the capital's own rocking on the
#: shaft's top joint (the joint's K_M is the shaft top's, the inertia the capital's) is a
#: mode too fast for a step integrator's budget: on a 0.5 m square shaft at k_n 5e9 Pa/m
#: a 0.1 m cube rocks at 7.7 kHz (0.4 million DOP853 steps for 10 s), a 5 cm one at 43
#: kHz (2.0 million, the default solver.max_steps), a 2 cm one at 430 kHz (the budget runs
#: out at 1.1 s). A smaller body on top is column.top_mass.
CAPITAL_RANGE = (0.1, LENGTH_RANGE[1])
DENSITY_RANGE = (1.0, 1e5)
#: Largest step and event budgets (a 64-bit count; 1e300 failed in the compiled kernel).
MAX_BUDGET = 1_000_000_000
#: Range of solver.max_wall_time, the wall-clock budget of one run [s].
WALL_TIME_RANGE = (0.0, 1e6)
MAX_FILE_BYTES = 1_000_000
DRUM_SUM_RTOL = 1e-9
NAME_RE = re.compile(r"[A-Za-z0-9_.\-]{1,100}")


def check_cell(
    kind: str, amplitude: Any, frequency: Any, *, options: bool = False
) -> tuple[float, float | None]:
    """(amplitude [g], frequency [Hz] or None) of one cell of an excitation of type ``kind``,
    checked against the grid's ranges (:data:`AMPLITUDE_RANGE_G`, :data:`FREQUENCY_RANGE_HZ`):
    the one check of a cell's amplitude and frequency, for the library and the command line.

    Parameters
    ----------
    kind : str  excitation.type: ``free`` has neither (0, 0), a ``record`` no frequency (None)
    amplitude : number or None  Peak ground acceleration [g]
    frequency : number or None  Excitation frequency [Hz]
    options : bool  Name them as the command line's options (``--amplitude``,
        ``--frequency``, checked when given whatever the type) instead of as the library's
        arguments (``amplitude_g``, ``frequency_hz``, numbers, not booleans)

    Raises
    ------
    RbmError  One line naming the argument, its range and the value given
    """
    ranges = {"amplitude": (AMPLITUDE_RANGE_G, "g"), "frequency": (FREQUENCY_RANGE_HZ, "Hz")}
    if options:
        if amplitude is not None and not (math.isfinite(amplitude) and amplitude >= 0.0):
            raise RbmError(f"--amplitude must be a finite number >= 0 [g], got {amplitude:g}")
        if frequency is not None and not (math.isfinite(frequency) and frequency > 0.0):
            raise RbmError(f"--frequency must be a finite number > 0 [Hz], got {frequency:g}")
        for name, value in (("amplitude", amplitude), ("frequency", frequency)):
            (lo, hi), unit = ranges[name]
            if value is not None and not lo <= value <= hi:
                raise RbmError(f"--{name} must be in [{lo:g}, {hi:g}] [{unit}], got {value:g}")
    if kind == "free":
        return 0.0, 0.0
    given = [("amplitude", amplitude)] + ([] if kind == "record" else [("frequency", frequency)])
    for name, value in given:
        (lo, hi), unit = ranges[name]
        if value is None:
            if options:
                raise RbmError(f"--{name} [{unit}] is required for excitation.type '{kind}'")
            raise RbmError(f"{name}_{unit.lower()} [{unit}] is required for excitation.type {kind}")
        if not options and not (finite_number(value) and lo <= value <= hi):
            raise RbmError(
                f"{name}_{unit.lower()} must be a number in [{lo:g}, {hi:g}] [{unit}],"
                f" got {shown(value)}"
            )
    return float(amplitude), None if kind == "record" else float(frequency)


def finite_number(value: Any) -> bool:
    """A finite real number: int, float or a numpy number (a 0-d array's), not a boolean."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        return False
    return not isinstance(value, np.complexfloating) and math.isfinite(value)


def shown(value: Any) -> str:
    """A value as a message shows it: numbers as written (a numpy number as its number),
    anything else by its repr, cut to 60 characters."""
    if isinstance(value, np.generic | np.ndarray) and np.ndim(value) == 0:
        value = value.item()
    if is_number(value):
        return fmt(value)
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def load_config(path: str | os.PathLike[str]) -> Config:
    """Read and validate a YAML config file.

    Parameters
    ----------
    path : str or path-like  The YAML file

    Returns
    -------
    Config  Validated, SI units (the grid in g and Hz)

    Raises
    ------
    ConfigError  File missing or unreadable, malformed YAML, or any key missing,
        unknown, of the wrong type or out of range; one line naming the key path.
    """
    source = os.fspath(path)
    file = Path(source)
    try:
        if file.is_dir():
            raise ConfigError(f"{source} is a directory, not a config file")
        if file.exists() and not file.is_file():
            raise ConfigError(f"{source} is not a regular file")
        with file.open("rb") as handle:
            raw = handle.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError(f"config file not found: {source}") from None
    except PermissionError:
        raise ConfigError(f"cannot read {source}: permission denied") from None
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise ConfigError(f"cannot read {source}: {one_line(str(reason))}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ConfigError(f"{source} is larger than {MAX_FILE_BYTES} bytes: not a config file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"cannot parse {source}: not UTF-8 text (bad byte at offset {exc.start})"
        ) from None
    return parse_config(read_yaml(text, source), source, base_dir=file.parent)


# ------------------------------------------------------------------------ sections


def parse_config(
    data: Mapping[str, Any],
    source: str = "<config>",
    base_dir: str | os.PathLike[str] | None = None,
) -> Config:
    """Validate the mapping a YAML config holds and build a :class:`Config`.

    Parameters
    ----------
    data : mapping  Parsed YAML or a dict (the configuration reference's keys; numpy numbers
        allowed)
    source : str  Where ``data`` came from, prefixed to error messages
    base_dir : path or None  Folder that relative paths in the config (a record's
        ``excitation.file``) are taken from; None: the current directory.
        :func:`load_config` passes the config file's folder.

    Returns
    -------
    Config  Validated, SI units (the grid in g and Hz)

    Raises
    ------
    ConfigError  One line: ``<source>: <key path> must be <allowed>, got <value>``.
    """
    try:
        written = plain_copy(data)  # numpy numbers (a notebook's) read as the numbers they are
        config = _config(written, base_dir)
        folder = os.getcwd() if base_dir is None else os.path.abspath(base_dir)
        config = dataclasses.replace(config, written=written, base_dir=folder)
        _check_uncertain(config, folder)
        points = expand(config, parse_config, base_dir=folder)  # each validates, or one line
        records = _axis_records(config, points)
        if records:
            config = dataclasses.replace(
                config, grid=dataclasses.replace(config.grid, records=records)
            )
    except ConfigError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return config


def _check_uncertain(config: Config, base_dir: str) -> None:
    """Each uncertain key at its distribution's median, then at the least and the largest
    value the design can draw (rbm_cli.config.uncertain.probe_values), set in the config as
    written and validated as a config: a key that is not one of the config, or that refuses
    a value the distribution can draw, is refused in one line naming the key."""
    if config.uncertain is None:
        return
    for path, distribution in config.uncertain.keys:
        for value in probe_values(distribution):
            try:
                _config(point_written(config.written, ((path, value),)), base_dir)
            except ConfigError as exc:
                raise ConfigError(
                    f"uncertain.keys.{path}: {distribution.text} can draw {fmt(value)}, which"
                    f" the key refuses ({exc}): bound it to the values the key takes"
                ) from None


def _axis_records(config: Config, points) -> tuple[tuple[str, str, str], ...]:
    """(key path, file as written, SHA-256) of each record file an axis of the grid names,
    in grid order, each once (rbm_cli.config.types.GridConfig.records)."""
    paths = [p for p in config.grid.axis_paths if p in RECORD_PATHS]
    out: dict = {}
    for point in points:
        for entry in point.config.record_files():
            if entry[0] in paths:
                out.setdefault(entry, None)
    return tuple(out)


def _config(data: Any, base_dir: str | os.PathLike[str] | None) -> Config:
    if data is None:
        raise ConfigError("the config is empty (it needs at least name and column)")
    if isinstance(data, Mapping) and "initial" in data:
        raise ConfigError("unknown key 'initial' at top level: it goes under excitation")
    top = hoist_suite(mapping(data, "", TOP_KEYS), base_dir)  # a suite: an axis of records
    if "name" not in top:
        raise ConfigError("name is required (the output folder name)")
    if "column" not in top:
        raise ConfigError("column is required (a mapping with height and base_width [m])")
    name = _name(top["name"])
    model = top.get("model", "rbm")
    if isinstance(model, str) and model in PLANNED_MODELS and model not in MODELS:
        raise ConfigError(
            f"model {model!r} is not available in this version (allowed: {', '.join(MODELS)})"
        )
    model = choice(model, "model", MODELS)
    column = _column(top["column"])
    n = column.n_drums
    for key in ("capital", "top_mass"):
        if not MODELS[model].beam and getattr(column, key) is not None:
            raise ConfigError(
                f"column.{key} is taken by model rbm only (model {model} has no such body):"
                " delete it or use model: rbm"
            )
    if model not in MULTI_DRUM_MODELS and n != 1:
        raise ConfigError(f"model {model!r} needs a monolithic column (drums: 1), got {n} drums")
    raw_interface = top.get("interface")
    stiffness = (
        raw_interface.get("stiffness", "rigid") if isinstance(raw_interface, Mapping) else "rigid"
    )
    if column.capital is not None and isinstance(stiffness, str) and stiffness == "rigid":
        raise ConfigError(
            "interface.stiffness: rigid needs a monolithic column, and column.capital is a drum"
            f" of its own ({n} drums): give {{rotational: K_M}} or {{normal: k_n}}"
        )
    beam_joint = "frame" in top and MODELS[model].beam and MODELS[model].frame
    interface = interface_section(top.get("interface"), n, model, beam_joint)
    excitation = excitation_section(top.get("excitation"), n, base_dir)
    config = Config(
        name=name,
        column=column,
        model=model,
        interface=interface,
        excitation=excitation,
        grid=parse_grid(top.get("grid")),
        collapse=CollapseConfig(
            ratio=number(
                mapping(top.get("collapse"), "collapse", COLLAPSE_KEYS).get("ratio", 1.0),
                "collapse.ratio",
                "",
                0.0,
                1.0,
            )
        ),
        solver=_solver(top.get("solver")),
        frame=_frame(top["frame"], model, column) if "frame" in top else None,
    )
    if top.get("uncertain") is not None:
        grid = config.grid
        uncertain = parse_uncertain(top["uncertain"], grid.axis_paths, grid.n_points, MAX_POINTS)
        config = dataclasses.replace(config, uncertain=with_design(uncertain))
    _check_dimensions(config)
    _check_stop(config)
    return config


def _check_stop(config: Config) -> None:
    """solver.stop: outcome stops by the energy of the Rigid Beam Model's laws, which bounds
    their arguments only where the energy is the laws' potential alone (`relative`)."""
    if config.solver.stop != "outcome":
        return
    formulation = config.interface.formulation
    if config.model != "rbm" or formulation != "relative":
        what = f"model {config.model}" if config.model != "rbm" else f"formulation {formulation}"
        raise ConfigError(
            "solver.stop: outcome needs model rbm with interface.formulation relative (its"
            f" energy certificate), got {what}: delete solver.stop"
        )


def _check_dimensions(config: Config) -> None:
    """A model that moves in three dimensions (Config.three_d) takes a circular column only;
    a planar model takes a motion along its plane only (excitation.angle 0, no
    excitation.file_y, so no suite of pairs either, no excitation.y); only the models in
    three dimensions (ModelEntry.three_d) take an initial state across the motion's plane."""
    model, excitation = config.model, config.excitation
    section = config.column.section
    init = excitation.initial
    if (init.rotations_across or init.velocities_across) and not MODELS[model].three_d:
        key = "rotations_across" if init.rotations_across else "velocities_across"
        spatial = ", ".join(name for name, entry in MODELS.items() if entry.three_d)
        why = (
            "starts its stack from one rotation and rate in the motion's plane"
            if MODELS[model].any_direction
            else "rocks in one plane"
        )
        raise ConfigError(
            f"excitation.initial.{key} is a state across the motion's plane, and model"
            f" {model} {why}: use a model in three dimensions ({spatial}) or delete it"
        )
    if config.three_d and config.frame is not None:
        raise ConfigError(
            f"frame rocks in one plane, and model {model} moves in three dimensions here (its"
            " motion given a direction or a second component): delete excitation.angle,"
            " excitation.y and excitation.file_y, or delete frame"
        )
    if config.three_d:
        if section != "circular":
            when = (
                ""
                if MODELS[model].three_d
                else " in three dimensions (its motion given a direction or a second component)"
            )
            raise ConfigError(
                f"model {model}{when} needs column.section: circular (a {section} section's"
                " rocking capacity is not the same in every direction)"
            )
        return
    three_d = ", ".join(
        name for name, entry in MODELS.items() if entry.three_d or entry.any_direction
    )
    if excitation.angle != 0.0:
        raise ConfigError(
            f"excitation.angle turns the motion out of the plane model {model} rocks in"
            f" (got {fmt(excitation.angle)} deg): use a model in three dimensions ({three_d})"
            " or delete excitation.angle"
        )
    if excitation.file_y is not None and excitation.motion is not None:
        raise ConfigError(
            f"motion {excitation.motion.name!r} is a pair (acceleration_y, a second horizontal"
            f" component), and model {model} rocks in one plane: use a model in three"
            f" dimensions ({three_d}) or give the motion without acceleration_y"
        )
    if excitation.file_y is not None:
        raise ConfigError(
            "excitation.file_y is a second horizontal component (so is the y of a pair"
            f" {{x, y}} in excitation.file), and model {model} rocks in one plane: use a model"
            f" in three dimensions ({three_d}) or delete excitation.file_y (write"
            " excitation.file as files, not pairs)"
        )
    if excitation.y is not None:
        raise ConfigError(
            "excitation.y is a second horizontal component, and model"
            f" {model} rocks in one plane: use a model in three dimensions ({three_d}) or"
            " delete excitation.y"
        )


def _name(value: Any) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"name must be a string (quote it), got {describe(value)}")
    if not NAME_RE.fullmatch(value) or set(value) == {"."}:
        raise ConfigError(
            "name must be a folder name of 1-100 letters A-Z a-z, digits and _ - . "
            f"(no spaces or slashes), got {describe(value)}"
        )
    return value


def _column(raw: Any) -> ColumnConfig:
    c = mapping(raw, "column", COLUMN_KEYS)
    for key in ("height", "base_width"):
        if key not in c:
            raise ConfigError(f"column.{key} is required (a number > 0 [m])")
    height = number(c["height"], "column.height", "m", 0.0)
    if not HEIGHT_RANGE[0] <= height <= HEIGHT_RANGE[1]:
        raise ConfigError(
            f"column.height must be in [{fmt(HEIGHT_RANGE[0])}, {fmt(HEIGHT_RANGE[1])}] [m]"
            f" (a laboratory block to a tower), got {fmt(height)}"
        )
    base = _bounded(number(c["base_width"], "column.base_width", "m", 0.0), "column.base_width")
    if base > height:
        raise ConfigError(
            f"column.base_width must be <= column.height ({fmt(height)} m), got {fmt(base)}"
            " (a block wider than tall is outside the model's intent)"
        )
    top = number(
        c.get("top_width", base),
        "column.top_width",
        "m",
        0.0,
        min(MAX_TOP_TAPER * base, height),
        hint=f"at most {fmt(MAX_TOP_TAPER)} x column.base_width and at most column.height",
    )
    top = _bounded(top, "column.top_width")
    section = choice(c.get("section", "rectangular"), "column.section", SECTIONS)
    depth = None
    if "depth" in c:
        if section != "rectangular":
            raise ConfigError(
                f"column.depth applies only to section: rectangular (section is {section};"
                " a circle's diameter is the width): delete it"
            )
        depth = _bounded(number(c["depth"], "column.depth", "m", 0.0), "column.depth")
    return ColumnConfig(
        height=height,
        base_width=base,
        top_width=top,
        section=section,
        depth=depth,
        density=_bounded(
            number(c.get("density", 2700.0), "column.density", "kg/m^3", 0.0),
            "column.density",
            "kg/m^3",
            DENSITY_RANGE,
        ),
        drum_heights=_drums(c.get("drums", 1), height),
        capital=_capital(c["capital"], section) if "capital" in c else None,
        top_mass=_top_mass(c["top_mass"]) if "top_mass" in c else None,
    )


def _frame(raw: Any, model: str, column: ColumnConfig) -> FrameConfig:
    """frame: {columns: N >= 2, beam_mass [kg] >= 0}, for a model that rocks frames
    (ModelEntry.frame)."""
    if raw is None:
        raise _empty("frame", "columns (an integer >= 2), beam_mass [kg]")
    f = mapping(raw, "frame", FRAME_KEYS, required=FRAME_KEYS)
    if not MODELS[model].frame:
        takes = ", ".join(name for name, entry in MODELS.items() if entry.frame)
        three = " (a frame rocks in one plane)" if MODELS[model].three_d else ""
        raise ConfigError(
            f"frame is taken by models {takes} in this version, not by model {model}{three}:"
            " delete frame or change the model"
        )
    columns = integer(f["columns"], "frame.columns", 2, MAX_FRAME_COLUMNS)
    beam = number(f["beam_mass"], "frame.beam_mass", "kg", 0.0, lo_open=False)
    beam = in_bounds(beam, "frame.beam_mass", "kg", BEAM_MASS_RANGE)
    if column.top_mass is not None:
        raise ConfigError(
            "column.top_mass and frame both put an entablature on the column: the frame's"
            " beam rests on every column top (frame.beam_mass); delete column.top_mass"
        )
    if not MODELS[model].multi_drum and column.top_width != column.base_width:
        raise ConfigError(
            f"model {model}'s frame is Makris and Vassiliou's equivalent block, exact for"
            " columns whose centre of mass is at half their diagonal: give a prismatic column"
            f" (column.top_width = base_width, got {fmt(column.top_width)} and"
            f" {fmt(column.base_width)} m) or use model rbm"
        )
    return FrameConfig(columns=columns, beam_mass=beam)


def _empty(path: str, keys: str) -> ConfigError:
    """The error of a body's section written without contents (``capital: null``)."""
    return ConfigError(f"{path} is empty (null): give {{{keys}}}, or delete {path}")


def _capital(raw: Any, section: str) -> CapitalConfig:
    """column.capital: {height, width, depth} [m], each in CAPITAL_RANGE."""
    path = "column.capital"
    if raw is None:
        raise _empty(path, "height, width [m]")
    c = mapping(raw, path, CAPITAL_KEYS)
    for key in ("height", "width"):
        if key not in c:
            raise ConfigError(f"{path}.{key} is required (a number > 0 [m])")
    height = _capital_length(c["height"], f"{path}.height")
    width = _capital_length(c["width"], f"{path}.width")
    depth = None
    if "depth" in c:
        if section != "rectangular":
            raise ConfigError(
                f"{path}.depth applies only to section: rectangular (section is {section};"
                " the capital's width is its diameter): delete it"
            )
        depth = _capital_length(c["depth"], f"{path}.depth")
    return CapitalConfig(height=height, width=width, depth=depth)


#: Why CAPITAL_RANGE, as its message says.
CAPITAL_WHY = (
    "the capital's own rocking on the shaft stays slow enough for a run's step budget; a"
    " smaller body on top is column.top_mass"
)


def _capital_length(value: Any, path: str) -> float:
    """A capital's height, width or depth [m], in CAPITAL_RANGE."""
    return in_bounds(number(value, path, "m", 0.0), path, "m", CAPITAL_RANGE, CAPITAL_WHY)


def _top_mass(raw: Any) -> TopMassConfig:
    """column.top_mass: {mass [kg], height_of_centre [m]}."""
    path = "column.top_mass"
    if raw is None:
        raise _empty(path, "mass [kg], height_of_centre [m]")
    t = mapping(raw, path, TOP_MASS_KEYS)
    if "mass" not in t:
        raise ConfigError(f"{path}.mass is required (a number > 0 [kg])")
    mass = _bounded(number(t["mass"], f"{path}.mass", "kg", 0.0), f"{path}.mass", "kg",
                    TOP_MASS_RANGE)  # fmt: skip
    centre = number(t.get("height_of_centre", 0.0), f"{path}.height_of_centre", "m", 0.0,
                    LENGTH_RANGE[1], lo_open=False)  # fmt: skip
    return TopMassConfig(mass=mass, height_of_centre=centre)


def _bounded(
    x: float, path: str, unit: str = "m", bounds: tuple[float, float] = LENGTH_RANGE
) -> float:
    """x within bounds (validate.in_bounds, lengths by default)."""
    return in_bounds(x, path, unit, bounds)


def _drums(value: Any, height: float) -> tuple[float, ...]:
    path = "column.drums"
    if not isinstance(value, list | tuple):
        count = integer(
            value, path, 1, MAX_DRUMS, " (count of equal drums) or a list of drum heights [m]"
        )
        return (height / count,) * count
    if not 1 <= len(value) <= MAX_DRUMS:
        got = f"{len(value)} heights" if value else "an empty list"
        raise ConfigError(f"{path} must list 1..{MAX_DRUMS} drum heights [m], got {got}")
    heights = number_list(value, path, "m", 0.0)
    for i, h in enumerate(heights):
        _bounded(h, join(path, i), "m", (1e-6, LENGTH_RANGE[1]))
    total = math.fsum(heights)
    if abs(total - height) > DRUM_SUM_RTOL * height:
        raise ConfigError(
            f"{path} heights sum to {fmt(total)} m but column.height is {fmt(height)} m"
            " (they must agree within 1e-9 relative)"
        )
    return heights


def _budget(value: Any, path: str, lo: int) -> int | None:
    """A run's budget: `auto` (None: it scales with the run, SolverConfig.for_run) or an
    integer in lo..MAX_BUDGET."""
    if value == "auto":
        return None
    return integer(value, path, lo, MAX_BUDGET, " or auto")


def _solver(raw: Any) -> SolverConfig:
    s = mapping(raw, "solver", SOLVER_KEYS)
    default = SolverConfig()
    return SolverConfig(
        method=choice(s.get("method", default.method), "solver.method", METHODS),
        rtol=number(s.get("rtol", default.rtol), "solver.rtol", "", 1e-13, 1e-3, lo_open=False),
        atol=number(s.get("atol", default.atol), "solver.atol", "", 0.0, 1e-3),
        max_steps=_budget(s.get("max_steps", "auto"), "solver.max_steps", 1000),
        max_events=_budget(s.get("max_events", "auto"), "solver.max_events", 100),
        time_step=number(
            s.get("time_step", default.time_step),
            "solver.time_step",
            "s",
            *TIME_STEP_RANGE,
            lo_open=False,
        ),
        implementation=choice(
            s.get("implementation", default.implementation),
            "solver.implementation",
            IMPLEMENTATIONS,
        ),
        max_wall_time=number(
            s.get("max_wall_time", default.max_wall_time),
            "solver.max_wall_time",
            "s",
            *WALL_TIME_RANGE,
        ),
        stop=choice(s.get("stop", default.stop), "solver.stop", STOPS),
    )
