"""The site's reference pages, generated from the code at build time so they cannot drift.

Three directives:

- ``.. rbm-cli::`` every command of the click group ``rbm_cli.cli.main:main``'s ``cli``
  with its usage, its help text (as ``rbm COMMAND --help`` prints it, once: its options are
  in the table, not repeated above it) and a table of its arguments and options (the
  flags; the help, the type and the default);
- ``.. rbm-domain-columns::`` the columns of domain.csv, in order, read from its schema
  (``rbm_cli.study.schema.columns``) and the registry of intensity measures;
- ``.. rbm-config::`` every key of the config: the key paths are read from the loader's key
  tuples (``rbm_cli.config.load.TOP_KEYS`` ...), the defaults from the config dataclasses
  (``rbm_cli.config.types``), the choices and most ranges from the loader's constants; the
  unit and the meaning of each key are written here, in :data:`KEY_DOCS`. A key the loader
  accepts and this table lacks (or the reverse) stops the build.

:func:`cli_rst`, :func:`config_rst` and :func:`domain_columns_rst` return the
reStructuredText the directives parse;
``tests/test_docs_reference.py`` checks that every option and every key appears in it.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import textwrap
from collections.abc import Iterator

import click

# ------------------------------------------------------------------------ text helpers
_RST_SPECIAL = "\\`*_|[]<>"


def esc(text: str) -> str:
    """Plain text as reStructuredText inline text (nothing in it is markup)."""
    out = []
    for ch in str(text):
        out.append("\\" + ch if ch in _RST_SPECIAL else ch)
    return " ".join("".join(out).split())


def lit(text: str) -> str:
    """Inline literal (``text``), or plain escaped text when it holds backquotes."""
    text = str(text)
    if "`" in text or not text.strip():
        return esc(text)
    return f"``{text}``"


def list_table(header: list[str], rows: list[list[str]], widths: list[int]) -> list[str]:
    lines = [
        ".. list-table::",
        "   :header-rows: 1",
        f"   :widths: {' '.join(str(w) for w in widths)}",
        "   :class: rbm-reference",
        "",
    ]
    for row in [header, *rows]:
        for k, cell in enumerate(row):
            lines.append(("   * - " if k == 0 else "     - ") + (cell if cell else "\\-"))
    lines.append("")
    return lines


def fmt(x: float) -> str:
    return f"{x:g}"


# ------------------------------------------------------------------------- the CLI
def cli_group() -> click.Group:
    """The click group the ``rbm`` console script runs (``rbm_cli.cli.main:main``)."""
    from rbm_cli.cli.main import cli

    return cli


def commands() -> Iterator[tuple[str, click.Command]]:
    group = cli_group()
    ctx = click.Context(group, info_name="rbm")
    for name in group.list_commands(ctx):
        yield name, group.get_command(ctx, name)


def _type_text(param: click.Parameter) -> str:
    if isinstance(param, click.Option) and param.is_flag:
        return "flag"
    t = param.type
    if isinstance(t, click.Choice):
        return " | ".join(str(c) for c in t.choices)
    if isinstance(t, click.IntRange | click.FloatRange):
        kind = "integer" if isinstance(t, click.IntRange) else "number"
        return f"{kind} {t._describe_range()}"
    name = getattr(t, "name", str(t))
    return {"text": "text", "integer": "integer", "float": "number"}.get(name, name)


def _metavar(param: click.Option) -> str:
    """The word after an option's flag: its metavar, its name for a choice (the choices
    are listed in the table's meaning), nothing for a flag."""
    if param.is_flag:
        return ""
    if param.metavar:
        return param.metavar
    if isinstance(param.type, click.Choice):
        return param.name.upper()
    return param.type.get_metavar(param, click.Context(click.Command("x"))) or param.name.upper()


def _default_text(param: click.Option) -> str:
    default = param.default
    unset = "sentinel" in type(default).__name__.lower()  # click's UNSET: no default
    if unset or param.is_flag or default is None or callable(default) or default == ():
        return ""
    return lit(default if not isinstance(default, tuple | list) else
               " ".join(str(d) for d in default))  # fmt: skip


def _option_row(param: click.Parameter) -> list[str]:
    """[the flags, the meaning]: its help, then its type and default in a line of their
    own. The choices of a choice are listed there, not beside the flag (a long
    ``[a|b|c]`` made the column too wide for the page)."""
    if isinstance(param, click.Argument):
        flags = lit(param.make_metavar(click.Context(click.Command("x"))))
        meaning = "Argument" + (" (required)." if param.required else ".")
        return [flags, meaning + "\n\n" + esc(_type_text(param))]
    assert isinstance(param, click.Option)
    metavar = _metavar(param)
    names = list(param.opts) + list(param.secondary_opts)
    flags = ", ".join(lit(n + (" " + metavar if metavar else "")) for n in names)
    if param.nargs and param.nargs > 1:
        flags += f" (takes {param.nargs} values)"
    if param.multiple:
        flags += " (repeatable)"
    kind = _type_text(param)
    if isinstance(param.type, click.Choice):
        kind = "one of " + ", ".join(lit(c) for c in param.type.choices)
    else:
        kind = esc(kind)
    default = _default_text(param)
    facts = f"*{kind}*" if not isinstance(param.type, click.Choice) else kind
    if default:
        facts += f"; default {default}"
    return [flags, esc(param.help or "") + "\n\n" + facts]


def help_rst(text: str) -> list[str]:
    """A click help text as reStructuredText: its paragraphs as text, each paragraph that
    click prints as written (one that starts with ``\\b``: examples, lists) as a literal
    block; what follows a ``\\f`` is not help."""
    text = inspect.cleandoc(text or "").split("\f")[0]
    lines: list[str] = []
    for para in re.split(r"\n\s*\n", text):
        if not para.strip():
            continue
        if para.lstrip().startswith("\b"):
            body = textwrap.dedent(para.lstrip()[1:].strip("\n"))
            lines += ["::", ""] + ["   " + line for line in body.splitlines()] + [""]
        else:
            lines += [esc(para), ""]
    return lines


def _cell(text: str, first: bool) -> list[str]:
    """A list-table cell whose text may hold paragraphs (split at blank lines)."""
    head = "   * - " if first else "     - "
    paras = text.split("\n\n") if text else ["\\-"]
    out = [head + paras[0]]
    for para in paras[1:]:
        out += ["", "       " + para]
    return out


def option_table(rows: list[list[str]], header: str = "option") -> list[str]:
    """The two-column table of a command's arguments and options (of the group's
    commands with ``header="command or option"``)."""
    lines = [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 32 68",
        "   :class: rbm-reference rbm-options",
        "",
    ]
    for row in [[header, "meaning"], *rows]:
        for k, cell in enumerate(row):
            lines += _cell(cell, k == 0)
    lines.append("")
    return lines


def cli_rst() -> str:
    """reStructuredText of every command: its usage, its help text once, and a table of its
    arguments and options (the options' help is in the table, not repeated above it)."""
    group = cli_group()
    lines: list[str] = []
    top = click.Context(group, info_name="rbm", **group.context_settings)
    lines += ["The ``rbm`` command", "-" * 19, "", ".. code-block:: text", ""]
    lines += ["   " + group.get_usage(top), ""]
    lines += help_rst(group.help)
    rows = [[lit(f"rbm {name}"), esc(cmd.get_short_help_str(limit=200))]
            for name, cmd in commands()]  # fmt: skip
    rows.append([lit("--version"), "Show the version and exit."])
    rows.append([lit("-h") + ", " + lit("--help"), "Show the help and exit."])
    lines += option_table(rows, header="command or option")
    for name, cmd in commands():
        ctx = click.Context(cmd, info_name=name, parent=top, **cmd.context_settings)
        title = f"rbm {name}"
        lines += [f".. _cli-{name}:", "", title, "-" * len(title), ""]
        lines += [".. code-block:: text", "", "   " + cmd.get_usage(ctx), ""]
        lines += help_rst(cmd.help)
        rows = [_option_row(p) for p in cmd.params]
        rows.append([lit("-h") + ", " + lit("--help"), "Show the help and exit."])
        lines += option_table(rows)
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------- the config
def config_keys() -> list[str]:
    """Every key path the config loader accepts, from its own key tuples."""
    from rbm_cli.config.excitation import (
        EXCITATION_KEYS,
        FILTER_KEYS,
        INITIAL_KEYS,
        PROCESSING_KEYS,
        Y_KEYS,
    )
    from rbm_cli.config.grid import EXCITATION_AXES, LINKED, VIRTUAL_PATHS
    from rbm_cli.config.interface import INTERFACE_KEYS, STIFFNESS_KEYS
    from rbm_cli.config.load import (
        CAPITAL_KEYS,
        COLLAPSE_KEYS,
        COLUMN_KEYS,
        FRAME_KEYS,
        SOLVER_KEYS,
        TOP_KEYS,
        TOP_MASS_KEYS,
    )
    from rbm_cli.config.uncertain import UNCERTAIN_KEYS

    nested = {
        "column": COLUMN_KEYS,
        "interface": INTERFACE_KEYS,
        "excitation": EXCITATION_KEYS,
        "collapse": COLLAPSE_KEYS,
        "solver": SOLVER_KEYS,
        "grid": (*EXCITATION_AXES, LINKED, *(p for p in VIRTUAL_PATHS), "<key path>"),
        "uncertain": (*(k for k in UNCERTAIN_KEYS if k != "keys"), "keys.<key path>"),
        "frame": FRAME_KEYS,
    }
    sub = {
        "interface.stiffness": STIFFNESS_KEYS,
        "excitation.initial": INITIAL_KEYS,
        "excitation.y": Y_KEYS,
        "excitation.processing": PROCESSING_KEYS,
        "excitation.processing.filter": FILTER_KEYS,
        "column.capital": CAPITAL_KEYS,
        "column.top_mass": TOP_MASS_KEYS,
    }

    def with_sub(path: str) -> list[str]:
        return [path] + [k for key in sub.get(path, ()) for k in with_sub(f"{path}.{key}")]

    keys: list[str] = []
    for top in TOP_KEYS:
        if top not in nested:
            keys.append(top)
            continue
        for key in nested[top]:
            keys += with_sub(f"{top}.{key}")
    return keys


def _defaults() -> dict[str, str]:
    """Defaults of the keys that have one, read from the config dataclasses."""
    from rbm_cli.config import types as t

    out: dict[str, str] = {}
    sections = {
        "": t.Config,
        "column": t.ColumnConfig,
        "column.capital": t.CapitalConfig,
        "column.top_mass": t.TopMassConfig,
        "interface": t.InterfaceConfig,
        "excitation": t.ExcitationConfig,
        "excitation.initial": t.InitialConfig,
        "excitation.y": t.SecondComponentConfig,
        "excitation.processing": t.ProcessingConfig,
        "excitation.processing.filter": t.FilterConfig,
        "collapse": t.CollapseConfig,
        "solver": t.SolverConfig,
    }
    for prefix, cls in sections.items():
        for f in dataclasses.fields(cls):
            if f.default is dataclasses.MISSING:
                continue
            value = f.default
            if value is None or value == ():
                continue
            text = fmt(value) if isinstance(value, float) else str(value)
            out[f"{prefix}.{f.name}" if prefix else f.name] = text
    return out


def _ranges() -> dict[str, str]:
    """Allowed values written from the loader's constants."""
    from rbm_cli.config import types as t
    from rbm_cli.config.excitation import (
        ANGLE_RANGE_DEG,
        DEFAULT_DURATION,
        FILTER_ORDER_MAX,
        GAMMA_MAX,
        IM_PERIOD_RANGE_S,
        INITIAL_MAX,
        MAX_DURATION,
        MAX_IM_PERIODS,
        PHASE_MAX,
        Y_PHASE_RANGE_DEG,
        Y_RATIO_MAX,
    )
    from rbm_cli.config.grid import AMPLITUDE_RANGE_G, FREQUENCY_RANGE_HZ, MAX_CELLS, MAX_POINTS
    from rbm_cli.config.interface import FRICTION_MAX, NORMAL_RANGE, ROTATIONAL_RANGE
    from rbm_cli.config.load import (
        BEAM_MASS_RANGE,
        CAPITAL_RANGE,
        DENSITY_RANGE,
        HEIGHT_RANGE,
        LENGTH_RANGE,
        MAX_BUDGET,
        MAX_DRUMS,
        MAX_FRAME_COLUMNS,
        MAX_TOP_TAPER,
        TIME_STEP_RANGE,
        TOP_MASS_RANGE,
        WALL_TIME_RANGE,
    )
    from rbm_cli.config.uncertain import MAX_SAMPLES

    def one_of(values) -> str:
        return ", ".join(f"``{v}``" for v in values)

    durations = ", ".join(f"{fmt(v)} ({k})" for k, v in DEFAULT_DURATION.items())
    return {
        "model": one_of(t.MODELS),
        "column.height": f"[{fmt(HEIGHT_RANGE[0])}, {fmt(HEIGHT_RANGE[1])}]",
        "column.base_width": f"> 0, <= height; in [{fmt(LENGTH_RANGE[0])}, {fmt(LENGTH_RANGE[1])}]",
        "column.top_width": f"<= {fmt(MAX_TOP_TAPER)} x base_width and <= height; "
        f">= {fmt(LENGTH_RANGE[0])}",
        "column.section": one_of(t.SECTIONS),
        "column.depth": f"[{fmt(LENGTH_RANGE[0])}, {fmt(LENGTH_RANGE[1])}], rectangular only",
        "column.density": f"[{fmt(DENSITY_RANGE[0])}, {fmt(DENSITY_RANGE[1])}]",
        "column.drums": f"a count 1-{MAX_DRUMS}, or a list of drum heights summing to height",
        "column.capital.height": f"[{fmt(CAPITAL_RANGE[0])}, {fmt(CAPITAL_RANGE[1])}]",
        "column.capital.width": f"[{fmt(CAPITAL_RANGE[0])}, {fmt(CAPITAL_RANGE[1])}]",
        "column.capital.depth": f"[{fmt(CAPITAL_RANGE[0])}, {fmt(CAPITAL_RANGE[1])}], "
        "rectangular only",
        "column.top_mass.mass": f"[{fmt(TOP_MASS_RANGE[0])}, {fmt(TOP_MASS_RANGE[1])}]",
        "column.top_mass.height_of_centre": f"[0, {fmt(LENGTH_RANGE[1])}]",
        "frame.columns": f"an integer 2-{MAX_FRAME_COLUMNS}",
        "frame.beam_mass": f"[{fmt(BEAM_MASS_RANGE[0])}, {fmt(BEAM_MASS_RANGE[1])}]",
        "interface.stiffness.rotational": f"[{fmt(ROTATIONAL_RANGE[0])}, "
        f"{fmt(ROTATIONAL_RANGE[1])}], one value or one per interface",
        "interface.stiffness.normal": f"[{fmt(NORMAL_RANGE[0])}, {fmt(NORMAL_RANGE[1])}]",
        "interface.formulation": one_of(t.FORMULATIONS),
        "interface.friction": f"(0, {fmt(FRICTION_MAX)}]",
        "interface.damping": "[0, 1); default 0 (undamped)",
        "excitation.type": one_of(t.EXCITATIONS),
        "excitation.duration": f"(0, {fmt(MAX_DURATION)}]; default {durations}",
        "excitation.phase": f"[-{fmt(PHASE_MAX)}, {fmt(PHASE_MAX)}]",
        "excitation.angle": f"[{fmt(ANGLE_RANGE_DEG[0])}, {fmt(ANGLE_RANGE_DEG[1])}]",
        "excitation.gamma": f"(1, {fmt(GAMMA_MAX)}]",
        "excitation.nu": "[-2 pi, 2 pi]",
        "excitation.units": one_of(t.RECORD_UNITS),
        "excitation.scale": one_of(t.RECORD_SCALES),
        "excitation.free_time": f"[0, {fmt(MAX_DURATION)}]",
        "excitation.processing.baseline": one_of(t.BASELINES),
        "excitation.processing.filter.order": f"an integer 1-{FILTER_ORDER_MAX}",
        "excitation.im_periods": f"[{fmt(IM_PERIOD_RANGE_S[0])}, {fmt(IM_PERIOD_RANGE_S[1])}]"
        f", distinct, at most {MAX_IM_PERIODS}",
        "excitation.initial.rotations": f"within +-{fmt(INITIAL_MAX['rotations'])}, one per drum",
        "excitation.initial.velocities": f"within +-{fmt(INITIAL_MAX['velocities'])}, one per drum",
        "excitation.initial.rotations_across": f"within +-{fmt(INITIAL_MAX['rotations'])}, one"
        " per drum; ``housner-3d``, ``rbm-3d``",
        "excitation.initial.velocities_across": f"within +-{fmt(INITIAL_MAX['velocities'])}, one"
        " per drum; ``housner-3d``, ``rbm-3d``",
        "excitation.y.amplitude_ratio": f"[0, {fmt(Y_RATIO_MAX)}]",
        "excitation.y.phase_deg": f"[{fmt(Y_PHASE_RANGE_DEG[0])}, {fmt(Y_PHASE_RANGE_DEG[1])}];"
        " ``ricker``: a multiple of 180",
        "grid.amplitudes": f"[{fmt(AMPLITUDE_RANGE_G[0])}, {fmt(AMPLITUDE_RANGE_G[1])}]",
        "grid.frequencies": f"[{fmt(FREQUENCY_RANGE_HZ[0])}, {fmt(FREQUENCY_RANGE_HZ[1])}]",
        "grid.<key path>": f"at most {MAX_CELLS:,} cells in all",
        "uncertain.samples": f"an integer 1-{MAX_SAMPLES:,}; samples x grid points at most"
        f" {MAX_POINTS:,}",
        "uncertain.seed": "an integer 0-4,294,967,295",
        "solver.method": one_of(t.METHODS),
        "solver.max_steps": f"auto ({t.BUDGET_PER_JOINT_SECOND['max_steps']:,} a second of "
        f"motion and a joint, at least {t.BUDGET_FLOOR['max_steps']:,}), or an integer "
        f"1,000-{MAX_BUDGET:,}",
        "solver.max_events": f"auto ({t.BUDGET_PER_JOINT_SECOND['max_events']:,} a second of "
        f"motion and a joint, at least {t.BUDGET_FLOOR['max_events']:,}), or an integer "
        f"100-{MAX_BUDGET:,}",
        "solver.time_step": f"[{fmt(TIME_STEP_RANGE[0])}, {fmt(TIME_STEP_RANGE[1])}]",
        "solver.max_wall_time": f"({fmt(WALL_TIME_RANGE[0])}, {fmt(WALL_TIME_RANGE[1])}]",
        "solver.implementation": one_of(t.IMPLEMENTATIONS),
        "solver.stop": one_of(t.STOPS),
    }


#: key path -> (unit, allowed values where no constant of the loader states them, meaning).
#: An empty allowed text takes the one :func:`_ranges` writes from the code.
KEY_DOCS: dict[str, tuple[str, str, str]] = {
    "name": ("", "letters, digits, ``_ - .`` (1-100)", "Required. The output folder's name."),
    "model": (
        "",
        "",
        "``rbm`` the Rigid Beam Model; ``housner`` Housner's exact block (large "
        "rotations, true geometry); ``housner-linear`` the piecewise-linear block of "
        "Spanos and Koh; both monolithic only; ``bullet`` the rigid-body contact "
        "engine (any drums; it ignores the joint law's stiffness, xi, restitution "
        "and formulation; free in three dimensions, circular drums only, when the motion "
        "is given a direction or a second component); ``housner-3d`` the rigid cylinder rocking and rolling on "
        "its rim in three dimensions (monolithic, ``column.section: circular``); "
        "``rbm-3d`` the Rigid Beam Model of circular drums in two horizontal directions "
        "(any drums, ``column.section: circular``).",
    ),
    "column.height": ("m", "", "Required. Height H of the column."),
    "column.base_width": ("m", "", "Required. Width B_1 at the base."),
    "column.top_width": (
        "m",
        "",
        "Width at the top; the width tapers linearly. Default: base_width.",
    ),
    "column.section": ("", "", "``circular``: the width is the diameter."),
    "column.depth": ("m", "", "Out-of-plane depth. Default: the local width (square drums)."),
    "column.density": ("kg/m^3", "", "Density of the stone."),
    "column.drums": ("", "", "Count of equal drums, or the list of drum heights [m]. Default 1."),
    "column.capital": (
        "",
        "a mapping; model ``rbm`` only",
        "A capital on top of the shaft: a drum of its own (one more interface, initial "
        "rotation and K_M) above column.height, rocking on the shaft's top section. Its "
        "mass is its volume times column.density. Its sizes are at least 0.1 m: its joint's "
        "K_M is the shaft top's and its inertia its own, so the smaller the capital the "
        "faster it rocks there, until a run exhausts the step budget (on a 0.5 m square "
        "shaft at k_n 5e9 Pa/m, a 10 s harmonic: a 0.1 m cube 7.7 kHz and 0.4 million "
        "DOP853 steps, 5 cm 43 kHz and 2.0 million, the default solver.max_steps; 2 cm "
        "430 kHz, failed at 1.1 s). A smaller body on top: column.top_mass. ``capital: "
        "null`` is refused (delete the key for no capital). Default: none.",
    ),
    "column.capital.height": ("m", "", "Required. The capital's own height (0 is refused)."),
    "column.capital.width": ("m", "", "Required. Its width (diameter for a circular column)."),
    "column.capital.depth": (
        "m",
        "",
        "Its out-of-plane depth, rectangular only. Default: its width (square).",
    ),
    "column.top_mass": (
        "",
        "a mapping; model ``rbm`` only",
        "A rigid point mass on the axis carried by the top drum (an architrave's share): "
        "part of that drum's mass, centre and inertia (parallel axis, no rotary inertia of "
        "its own), and of the normal force of every joint. ``top_mass: null`` is refused. "
        "Default: none.",
    ),
    "column.top_mass.mass": ("kg", "", "Required. Its mass."),
    "column.top_mass.height_of_centre": (
        "m",
        "",
        "Height of its centre above the top drum's top face.",
    ),
    "interface": ("", "", ""),
    "interface.stiffness": (
        "",
        "``rigid``, ``{rotational: K_M}`` or ``{normal: k_n}``",
        "Joint stiffness. ``rigid`` (monolithic columns only) is the "
        "default. A bare number is refused: it does not say which of "
        "the two it is.",
    ),
    "interface.stiffness.rotational": (
        "N m/rad",
        "",
        "K_M of every joint, or a list with one per interface.",
    ),
    "interface.stiffness.normal": (
        "Pa/m",
        "",
        "k_n; K_M,i = k_n depth_i B_i^3 / 12 "
        "(rectangle), k_n pi B_i^4 / 64 (circle). ``rbm info`` "
        "prints both.",
    ),
    "interface.xi": ("", "(0, 1]", "1: bilinear law; < 1: tri-linear (a plateau at xi M_u)."),
    "interface.restitution": (
        "",
        "(0, 1] or ``housner`` (monolithic only)",
        "Ratio of angular velocities after and before an impact.",
    ),
    "interface.formulation": (
        "",
        "",
        "Which rotation the joint law reads: ``relative`` "
        "(theta_i - theta_(i-1)), ``absolute`` (theta_i, the paper's "
        "literal wording), ``geometric`` (the law without its "
        "rigid-stack P-Delta; gravity through the displaced drums).",
    ),
    "interface.friction": (
        "",
        "",
        "Coulomb coefficient of every joint and the base. ``model: bullet``: its "
        "contacts' friction (default 1). ``model: rbm`` (which cannot slide): the "
        "coefficient its friction demand ``max |T_i/N_i|`` is checked against; a run "
        "reports where the demand first exceeded it and domain.csv gains ``slides`` "
        "(0/1; no key: not checked, no column). Refused for the other models.",
    ),
    "interface.damping": (
        "",
        "",
        "Ratio zeta of critical damping of the column's first elastic mode: viscous "
        "damping of each joint while it is on its elastic branch, proportional to its "
        "stiffness (none once it lifts). ``model: rbm`` with a finite "
        "``interface.stiffness``; the Runge-Kutta methods (``auto`` takes DOP853).",
    ),
    "excitation.type": (
        "",
        "",
        "The ground motion: harmonic, half-sine, free motion, the "
        "near-fault pulses, or a record file.",
    ),
    "excitation.duration": (
        "s",
        "",
        "Simulated time. Half-sine and pulses: the maximum "
        "(the whole pulse is always simulated). Not for ``record``.",
    ),
    "excitation.phase": ("rad", "", "Phase of a harmonic excitation."),
    "excitation.file_y": (
        "",
        "a file sampled as ``file``; a list, a folder or a glob beside ``file``'s",
        "``record`` only, models in three dimensions: the record's second horizontal "
        "component, at 90 degrees counter-clockwise from ``file`` (a station's two "
        "components). Same formats and units; scaled by the same factor, with "
        "``scale: pga`` the larger of the two components' PGAs is the amplitude. "
        "Beside a list, folder or glob in ``file``, a list, folder or glob of as many "
        "files: a suite of pairs, the k-th file of each (a list's as written, a folder's "
        "or a glob's sorted) one record, named as its x file. Not with pairs in ``file``.",
    ),
    "excitation.angle": (
        "deg",
        "",
        "Azimuth in plan of the horizontal motion, from the x axis (any type: the motion "
        "is turned to it). Models in three dimensions only (``housner-3d``, ``rbm-3d``, "
        "and ``bullet``: written, 0 included, it runs the engine free in three "
        "dimensions); the planar models rock in the x plane and refuse any other. "
        "Default 0.",
    ),
    "excitation.initial": ("", "", "Initial state of the drums."),
    "excitation.initial.rotations": (
        "rad",
        "",
        "Absolute rotation of each drum at t = 0, in the motion's vertical plane (the x "
        "plane of the planar models; ``excitation.angle``'s for the models in three "
        "dimensions).",
    ),
    "excitation.initial.velocities": (
        "rad/s",
        "",
        "Angular velocity of each drum at t = 0, in the motion's vertical plane.",
    ),
    "excitation.initial.rotations_across": (
        "rad",
        "",
        "Models in three dimensions: each drum's rotation at t = 0 in the vertical plane "
        "across the motion's (its direction turned by +90 degrees, a history's "
        "``theta<i>_across_rad``): with ``rotations`` a rotation vector, rotations d + "
        "rotations_across d'. ``housner-3d``: the column tilts by the vector's size toward "
        "its direction. Refused by the planar models and ``bullet``. Default 0.",
    ),
    "excitation.initial.velocities_across": (
        "rad/s",
        "",
        "Models in three dimensions: each drum's rate at t = 0 across the motion's plane; "
        "the rates form a vector as the rotations do (the top moves along velocities d + "
        "velocities_across d'). ``housner-3d``: its angular velocity is horizontal, no "
        "spin about the vertical. A tilt in the plane with a rate across it starts a "
        "wobble. Refused by the planar models and ``bullet``. Default 0.",
    ),
    "excitation.y": (
        "",
        "a mapping",
        "``harmonic``, ``half-sine`` and the pulses, models in three dimensions: an "
        "analytic second horizontal component at 90 degrees counter-clockwise from the "
        "motion's direction (``excitation.angle`` turns both, as a record pair), the "
        "same formula times ``amplitude_ratio`` r, its phase led by ``phase_deg`` phi: a "
        "harmonic's a_y = r A sin(omega t + phase + phi); a sine pulse's the same on the "
        "pulse (the cycloidal's phase is 90 degrees); ``mavroeidis-papageorgiou``'s the "
        "pulse with nu + phi and r times its velocity amplitude; ``ricker``'s the wavelet "
        "times r (phi 0 or 360) or -r (phi 180). r = 1, phi = 90 is a circular motion; the "
        "grid's amplitude is the first component's. r = 0 is the motion of one component. "
        "Refused for records (their second component is ``file_y``), free motion and "
        "the planar models.",
    ),
    "excitation.y.amplitude_ratio": (
        "",
        "",
        "Required. r: the second component's multiplier over the first's.",
    ),
    "excitation.y.phase_deg": ("deg", "", "phi: the second component's phase lead."),
    "excitation.file": (
        "",
        "a file, a list of files, a folder, a glob, or a list of ``{x: FILE, y: FILE}``",
        "``record`` only: a PEER NGA ``.AT2`` or CSV (time [s], "
        "acceleration) file, relative to the config's folder. Several files "
        "are a suite: the grid axis ``excitation.file``. A list of pairs "
        "``{x, y}`` (models in three dimensions, no ``file_y``) is a suite of pairs, "
        "the x and y files a record's two horizontal components (as ``file`` and "
        "``file_y``): a grid axis linking ``excitation.file`` and ``excitation.file_y``, "
        "each pair named as its x file.",
    ),
    "excitation.units": (
        "",
        "",
        "``record`` only: the CSV's acceleration unit (an ``.AT2`` is in g).",
    ),
    "excitation.free_time": (
        "s",
        "",
        "``record`` only: free motion simulated after the record's last sample.",
    ),
    "excitation.im_periods": (
        "s",
        "",
        "``record`` only: periods of the 5 %-damped spectral accelerations "
        "``sa_<T>s_g`` a domain's rows report (beside ``sa_t1_g`` at the column's "
        "first elastic period); no effect on a run. Default none.",
    ),
    "excitation.scale": (
        "",
        "",
        "``record`` only: ``pga`` the grid amplitude is the scaled "
        "record's PGA [g]; ``factor`` a plain scale factor.",
    ),
    "excitation.gamma": (
        "",
        "",
        "``mavroeidis-papageorgiou`` only: the pulse's gamma. Required there.",
    ),
    "excitation.nu": (
        "rad",
        "",
        "``mavroeidis-papageorgiou`` only: the pulse's phase nu. Required there.",
    ),
    "excitation.vertical": (
        "",
        "a file",
        "``record`` only: the ground's upward "
        "acceleration, scaled as the horizontal record; every weight "
        "then acts with g + a_v(t).",
    ),
    "excitation.processing": (
        "",
        "",
        "``record`` only: how the record (and the vertical record) is "
        "processed before it is scaled: band-passed, then its baseline "
        "removed. With ``scale: pga`` the amplitude is the processed "
        "record's PGA. Part of the config's hash.",
    ),
    "excitation.processing.baseline": (
        "",
        "",
        "The polynomial in time removed from the acceleration: ``none``, "
        "``linear`` (a0 + a1 t) or ``quadratic`` (+ a2 t^2), fitted by "
        "least squares to the record's displacement (integrated from rest). "
        "Any time steps.",
    ),
    "excitation.processing.filter": (
        "",
        "a mapping",
        "A zero-phase Butterworth band-pass (a high-pass at ``low_hz``, a "
        "low-pass at ``high_hz``, run forward and backward). It needs a "
        "record at even time steps: one with uneven steps is refused.",
    ),
    "excitation.processing.filter.low_hz": (
        "Hz",
        "> 0, < high_hz",
        "Corner of the high-pass side. Required.",
    ),
    "excitation.processing.filter.high_hz": (
        "Hz",
        "> low_hz, < the record's Nyquist frequency 1 / (2 dt)",
        "Corner of the low-pass side. Required.",
    ),
    "excitation.processing.filter.order": (
        "",
        "",
        "Order n of each side: gain 1 / (1 + (f / f_c)^(2n)) a side, squared by the backward pass.",
    ),
    "grid.amplitudes": (
        "g",
        "",
        "A value, a list, or ``{start, stop, step}`` / "
        "``{start, stop, num}`` (stop included). Peak ground acceleration; "
        "a record's PGA (``scale: pga``).",
    ),
    "grid.frequencies": ("Hz", "", "As amplitudes. Not needed for records or free motion."),
    "grid.linked": (
        "",
        "a list of mappings of key paths to lists of one length",
        "Axes that vary together (e.g. ``column.height`` with ``column.base_width``).",
    ),
    "grid.column.size": (
        "m",
        "> 0",
        "Virtual axis: the height of a geometrically similar "
        "column (every length scaled by size / height).",
    ),
    "grid.column.slenderness": (
        "",
        "> 0",
        "Virtual axis: H / B_1 (top width and depth scale with the base width).",
    ),
    "grid.<key path>": (
        "the key's",
        "",
        "An axis over any config key inside a section, "
        "named by its dotted path (``column.height``, "
        "``interface.restitution``, ``column.drums``, ``excitation.file`` "
        "...); values as amplitudes, a range may add ``spacing: log``. "
        "``name`` and ``model`` cannot vary.",
    ),
    "frame.columns": (
        "",
        "models ``rbm``, ``housner``, ``housner-linear``, ``bullet`` (2 only)",
        "Required. A colonnade's bay: this many identical columns N (each the ``column``"
        " section) standing in a row in the plane of the motion under one rigid beam (an"
        " architrave) resting freely on their tops. In the plane only (no"
        " ``excitation.angle`` or second component). ``rbm``: every joint carries the"
        " beam's share, the beam rests on its own joint at the top (the formulation"
        " ``relative`` only); ``housner`` and ``housner-linear``: Makris and Vassiliou's"
        " equivalent block (prismatic columns); ``bullet``: the columns and a free beam in"
        " the engine. Without ``frame``: a column standing alone.",
    ),
    "frame.beam_mass": (
        "kg",
        "",
        "Required. The whole beam's mass m_b; gamma = m_b / (N m), m a column's mass (rbm"
        " info gives gamma and the frame's figures). 0: the columns standing alone, the"
        " free column's run to the bit.",
    ),
    "uncertain.samples": (
        "",
        "",
        "Samples of the uncertain keys per cell of the grid: a sweep runs every cell once per"
        " sample (a row each). Required.",
    ),
    "uncertain.seed": (
        "",
        "",
        "Seed of the Latin hypercube (scipy.stats.qmc.LatinHypercube): the same seed draws"
        " the same design.",
    ),
    "uncertain.keys.<key path>": (
        "the key's",
        "",
        "A numeric config key by its dotted path (``interface.stiffness.normal``,"
        " ``interface.restitution``, ``column.density``, ``column.size`` ...) and one"
        " distribution: ``{lognormal: {median, beta}}``, ``{normal: {mean, std, bounds: [lo,"
        " hi]}}`` (bounds optional: truncated), ``{truncnorm: {mean, std, bounds}}``,"
        " ``{uniform: [lo, hi]}``. A distribution that can draw a value the key refuses is"
        " refused when the config loads. Not ``name``, ``model``, ``grid`` nor an axis of"
        " the grid.",
    ),
    "collapse.ratio": (
        "",
        "(0, 1]",
        "Collapse when the quantity the law reads reaches ratio x its limit.",
    ),
    "solver.method": (
        "",
        "",
        "``auto``: the rigid block's compiled closed form where it "
        "applies, DOP853 elsewhere; ``DOP853``, ``RK45``, ``RK23`` the step "
        "integrator; ``closed-form`` the rigid block; ``exact`` closed-form "
        "integration of the linear pieces (see the user guide).",
    ),
    "solver.rtol": ("", "[1e-13, 1e-3]", "Relative tolerance of the step integrator."),
    "solver.atol": (
        "",
        "(0, 1e-3]",
        "Absolute tolerance, relative to theta_u (rates: 10 theta_u).",
    ),
    "solver.max_steps": (
        "",
        "",
        "Step budget of one run: beyond it the run is ``failed`` and its message names the "
        "budget to raise. Default ``auto``: it grows with the motion's duration (its free "
        "time included) and the column's joints, so a tall column under a long record runs.",
    ),
    "solver.max_events": (
        "",
        "",
        "Event budget of one run (uplifts, impacts, kinks): beyond it the run is ``failed`` "
        "and its message names the budget to raise. Default ``auto``: it grows with the "
        "motion's duration and the column's joints.",
    ),
    "solver.time_step": ("s", "", "The contact engine's fixed step (``model: bullet``)."),
    "solver.implementation": (
        "",
        "",
        "``python`` runs the compiled source uncompiled, for "
        "debugging (the same bits, 30-100x slower).",
    ),
    "solver.max_wall_time": (
        "s",
        "",
        "Wall-clock budget of one run; beyond it the run is "
        "``failed``. Not part of the config's hash.",
    ),
    "solver.stop": (
        "",
        "",
        "When a sweep's run may end before its motion does. ``figures``: once no figure "
        "can change (a monolith past a peak of free motion below its collapse barrier). "
        "``outcome`` (model ``rbm``, formulation ``relative``): once its survival is "
        "certain (free motion, the column's energy below every joint's collapse barrier); "
        "the peaks and the friction demand are then those up to the stop. See the user "
        "guide (Solvers and methods, Stopping early).",
    ),
}
#: Keys that are sections of their own (their sub-keys have rows).
_SECTION_ROWS = {"interface"}


def config_rst() -> str:
    """reStructuredText of every config key: a table per section."""
    keys = config_keys()
    missing = [k for k in keys if k not in KEY_DOCS]
    extra = [k for k in KEY_DOCS if k not in keys and k not in _SECTION_ROWS]
    if missing or extra:
        raise ValueError(
            "docs/_ext/rbm_reference.py KEY_DOCS is out of step with the config loader: "
            f"keys without a description {missing}, described keys the loader lacks {extra}"
        )
    defaults, ranges = _defaults(), _ranges()
    groups: dict[str, list[str]] = {}
    for key in keys:
        groups.setdefault(key.split(".")[0] if "." in key else "top level", []).append(key)
    lines: list[str] = []
    for section, section_keys in groups.items():
        title = "Top-level keys" if section == "top level" else f"``{section}``"
        lines += [f".. _config-{section.replace(' ', '-')}:", "", title, "-" * len(title), ""]
        rows = []
        for key in section_keys:
            unit, allowed, meaning = KEY_DOCS[key]
            allowed = allowed or ranges.get(key, "")
            default = defaults.get(key, "")
            rows.append([
                f"``{key}``", esc(unit), f"``{default}``" if default else "\\-",
                allowed, meaning,
            ])  # fmt: skip
        lines += list_table(["key", "unit", "default", "allowed", "meaning"], rows,
                            [22, 8, 10, 22, 38])  # fmt: skip
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- domain.csv's columns
def domain_columns_rst() -> str:
    """reStructuredText of domain.csv's columns, in the order the writer writes them: a
    table read from the schema (rbm_cli.study.schema.columns()), the intensity measures'
    rows from their registry (rbm_cli.study.intensities.MEASURES, with how each scales with
    the record's factor)."""
    from rbm_cli.study.intensities import MEASURES
    from rbm_cli.study.schema import columns

    words = {"float": "number", "int": "whole number", "0/1": "0 or 1", "str": "text"}
    rows = [[lit("<path>"), "text or number", "", esc(
        "one column per grid axis over a config key, named by its path (column.size,"
        " excitation.file, ...; none for an amplitude x frequency grid)"), ""]]  # fmt: skip
    for column in columns():
        what = esc(column.quantity)
        measure = {m.column: m for m in MEASURES}.get(column.name)
        if measure is not None:
            if measure.period == "im_periods":
                what += esc(" (sa_0p5s_g: 0.5 s)")
            what += esc(f"; scales with the record's factor c: {measure.scaling}")
        rows.append([lit(column.name), words[column.dtype], esc(column.unit), what,
                     esc(column.filled or "every domain")])  # fmt: skip
    return "\n".join(
        list_table(
            ["column", "type", "unit", "what it holds", "written for"], rows, [22, 10, 7, 40, 21]
        )  # fmt: skip
    )


# --------------------------------------------------------------------- the directives
def setup(app):  # pragma: no cover - exercised by the docs build
    from docutils import nodes
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective

    class _Generated(SphinxDirective):
        has_content = False
        make = staticmethod(lambda: "")

        def run(self):
            text = self.make()
            container = nodes.section()
            container.document = self.state.document
            self.state.nested_parse(
                StringList(text.splitlines(), source="<rbm reference>"), 0, container,
                match_titles=True,
            )  # fmt: skip
            return container.children

    class CliDirective(_Generated):
        make = staticmethod(cli_rst)

    class ConfigDirective(_Generated):
        make = staticmethod(config_rst)

    class DomainColumnsDirective(_Generated):
        make = staticmethod(domain_columns_rst)

    app.add_directive("rbm-cli", CliDirective)
    app.add_directive("rbm-config", ConfigDirective)
    app.add_directive("rbm-domain-columns", DomainColumnsDirective)
    return {"parallel_read_safe": True, "version": "1"}


if __name__ == "__main__":  # python docs/_ext/rbm_reference.py: print them
    print(cli_rst())
    print(config_rst())
    print(domain_columns_rst())
