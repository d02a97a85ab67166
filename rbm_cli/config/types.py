"""Validated configuration: frozen dataclasses in SI units.

The YAML loader (:mod:`rbm_cli.config.load`) builds these; everything downstream
(column, law, model, integrator, sweep) reads only these objects, never YAML.
Amplitudes stay in g and frequencies in Hz only in :class:`GridConfig`, the
edge of the program; physics code converts with :data:`G`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from rbm_cli.config.uncertain import UncertainConfig

#: Acceleration of gravity [m/s^2] (g = 9.81, the value the paper and the reference blocks use).
G = 9.81

SECTIONS = ("rectangular", "circular")
FORMULATIONS = ("relative", "absolute", "geometric")
#: Near-fault pulses (one cycle or wavelet, then free motion), by the rocking literature's
#: names: amplitude [g] and frequency [Hz] from the grid, as the half-sine.
PULSES = ("one-sine", "cycloidal", "ricker", "mavroeidis-papageorgiou")
EXCITATIONS = ("harmonic", "half-sine", "free", *PULSES, "record")
#: Keys that apply to some excitation types only (key -> those types); a resolved config
#: (Config.resolved) leaves out those of other types.
ONLY_FOR = {
    "duration": tuple(t for t in EXCITATIONS if t != "record"),
    "file": ("record",),
    "units": ("record",),
    "free_time": ("record",),
    "scale": ("record",),
    "gamma": ("mavroeidis-papageorgiou",),
    "nu": ("mavroeidis-papageorgiou",),
    "vertical": ("record",),
    "file_y": ("record",),
    "processing": ("record",),
    "im_periods": ("record",),
    "y": tuple(t for t in EXCITATIONS if t not in ("record", "free")),
}
#: Units of a record file's accelerations (excitation.units) and how a record is scaled to
#: the grid's amplitude (excitation.scale: its PGA [g], or a plain factor).
RECORD_UNITS = ("g", "m/s2")
RECORD_SCALES = ("pga", "factor")
#: Baseline corrections of a record (excitation.processing.baseline): the degree of the
#: polynomial removed from its acceleration (none; linear: a0 + a1 t; quadratic: + a2 t^2).
BASELINES = ("none", "linear", "quadratic")
#: Default free motion after a record's last sample [s] (excitation.free_time)
#: [assumption]: a few rocking half-periods of a stone column (0.5-2 s each), so a column
#: still rocking when the shaking ends has time to collapse or settle; a monolithic
#: column whose energy is below its collapse barrier is stopped early anyway.
DEFAULT_FREE_TIME = 5.0
METHODS = ("auto", "DOP853", "RK45", "RK23", "exact", "exact-first", "closed-form")
#: Excitations with a closed-form response (sines, and records exact per sample interval):
#: what `solver.method: closed-form` (and `exact`) take (rbm_cli.models.methods).
CLOSED_FORM_KINDS = ("harmonic", "half-sine", "free", "one-sine", "cycloidal", "record")
#: The method `auto` stands for where the closed form does not apply, and in a config's
#: hash (the default before `auto` existed: the hashes of stored domains stay valid).
STEP_DEFAULT = "DOP853"
IMPLEMENTATIONS = ("compiled", "python")
#: When a run may end before its motion does (solver.stop). figures: once no figure of the
#: run can change (a monolith past a peak of free motion below its collapse barrier);
#: outcome: once its outcome cannot change (free motion of any column below every joint's
#: collapse barrier; the peaks are then those up to the stop).
STOPS = ("figures", "outcome")


@dataclass(frozen=True)
class ModelEntry:
    """A registered model: its runner ("module:class", rbm_cli.models.contract.Runner),
    whether it takes more than one drum, whether it moves in three dimensions (a
    circular section only, a motion in any direction: excitation.angle), whether it moves
    in three dimensions when its motion is given a direction or a second component and in
    the plane otherwise (``any_direction``: Config.three_d), whether its joints are the
    Rigid Beam Model's (their laws, stiffness and damping, a capital or a top mass, the
    friction demand), whether its drums may slide for good (``residual``: its runs
    give a residual slip, top offset and tilt, Outcome.residual_slip and the like), and
    whether it rocks a frame of columns under a beam (``frame``: Config.frame)."""

    runner: str
    multi_drum: bool
    three_d: bool = False
    beam: bool = False
    any_direction: bool = False
    residual: bool = False
    frame: bool = False


#: The model registry, name -> runner (rbm_cli.models.registry resolves it). rbm: the
#: Rigid Beam Model; housner: Housner's nonlinear rigid block (large rotations, true
#: geometry); housner-linear: the piecewise-linear block of Spanos and Koh (closed form,
#: true geometry); the last two monolithic only. bullet: stacked rigid drums in Bullet's
#: contact dynamics (PyBullet), any drums, in the plane or free in three dimensions
#: (circular drums, when the motion is given a direction or a second component).
#: housner-3d: the rigid cylinder rocking and rolling on its rim in three dimensions (true
#: geometry, circular monolithic columns).
#: rbm-3d: the Rigid Beam Model in two horizontal directions (circular drums).
#: A new model is one module and one line here.
MODELS = {
    "rbm": ModelEntry(
        "rbm_cli.models.rbm.runner:RbmRunner", multi_drum=True, beam=True, frame=True
    ),
    "housner": ModelEntry(
        "rbm_cli.models.housner.runner:HousnerRunner", multi_drum=False, frame=True
    ),
    "housner-linear": ModelEntry(
        "rbm_cli.models.block.runner:HousnerLinearRunner", multi_drum=False, frame=True
    ),
    "bullet": ModelEntry(
        "rbm_cli.models.bullet.run:BulletRunner",
        multi_drum=True,
        any_direction=True,
        residual=True,
        frame=True,
    ),
    "housner-3d": ModelEntry(
        "rbm_cli.models.housner3d.runner:Housner3dRunner", multi_drum=False, three_d=True
    ),
    "rbm-3d": ModelEntry(
        "rbm_cli.models.rbm3d.runner:Rbm3dRunner", multi_drum=True, three_d=True, beam=True
    ),
}


@dataclass(frozen=True)
class CapitalConfig:
    """A capital: a drum of its own on top of the shaft (the column's height does not
    include it). It rocks on the shaft's top section (its joint is the shaft's top width
    wide); its mass is its own volume times the column's density.

    height : float  Its height [m]
    width : float  Its width, or diameter for a circular column [m]
    depth : float or None  Out-of-plane depth [m] (rectangular only); None = its width
    """

    height: float
    width: float
    depth: float | None = None


@dataclass(frozen=True)
class TopMassConfig:
    """A rigid point mass carried by the top drum (an architrave's share), on the column's
    axis.

    mass : float  Its mass [kg]
    height_of_centre : float  Height of its centre above the top drum's top face [m]
    """

    mass: float
    height_of_centre: float = 0.0


@dataclass(frozen=True)
class FrameConfig:
    """A frame (a colonnade's bay): ``columns`` identical columns, each the config's
    ``column``, standing in a row in the plane of the motion under one rigid beam (an
    architrave) that rests freely on their tops.

    columns : int  N, the number of columns (>= 2)
    beam_mass : float  The whole beam's mass [kg] (0: the columns stand free)
    """

    columns: int
    beam_mass: float

    def ratio(self, column_mass: float) -> float:
        """gamma = m_beam / (N m), the beam's mass over the columns' [-], for a column of
        mass ``column_mass`` [kg]."""
        return self.beam_mass / (self.columns * column_mass)


@dataclass(frozen=True)
class ColumnConfig:
    """Geometry and material of the column.

    height : float  Total height H [m]
    base_width : float  Width B_1 at z = 0 [m]
    top_width : float  Width at z = H [m]
    section : str  'rectangular' or 'circular'
    depth : float or None  Out-of-plane depth [m] (rectangular only); None = local width
    density : float  Mass density [kg/m^3]
    drum_heights : tuple of float  Heights h_i of the shaft's drums, bottom first [m]
    capital : CapitalConfig or None  A capital on top of the shaft: one more drum
    top_mass : TopMassConfig or None  A point mass carried by the top drum
    """

    height: float
    base_width: float
    top_width: float
    section: str = "rectangular"
    depth: float | None = None
    density: float = 2700.0
    drum_heights: tuple[float, ...] = ()
    capital: CapitalConfig | None = None
    top_mass: TopMassConfig | None = None

    @property
    def n_drums(self) -> int:
        """Drums of the model: the shaft's, and the capital if there is one (so also the
        number of interfaces, of initial rotations and of per-interface stiffnesses)."""
        return len(self.drum_heights) + (self.capital is not None)


@dataclass(frozen=True)
class StiffnessConfig:
    """Interface bending stiffness.

    kind : str  'rigid' (K_M = infinity), 'moment' (K_M given [N m/rad]) or
        'normal' (joint normal stiffness k_n [Pa/m])
    values : tuple of float  For 'moment': one value, or one per interface
        [N m/rad]; for 'normal': (k_n,) [Pa/m]; for 'rigid': ()
    """

    kind: str = "rigid"
    values: tuple[float, ...] = ()


@dataclass(frozen=True)
class InterfaceConfig:
    """Moment-rotation law of the interfaces.

    restitution : float or str  Angular-velocity ratio in (0, 1], or 'housner'
    friction : float  Coulomb friction coefficient of the joints and the base
        (model bullet's contacts; the RBM and the reference models do not slide) [-]
    friction_limit : float or None  The friction coefficient the RBM's friction demand
        max |T_i / N_i| is checked against (interface.friction given for rbm or rbm-3d): a run
        says where the demand first exceeds it and a domain marks the cells it does
        (``slides``); None: not checked [-]
    damping : float  Ratio zeta of critical damping of the column's first elastic mode,
        in [0, 1): viscous damping of the joints on their elastic branch, proportional to
        their stiffness (model rbm with a finite interface.stiffness; 0: undamped) [-]
    """

    stiffness: StiffnessConfig = field(default_factory=StiffnessConfig)
    xi: float = 1.0
    restitution: float | str = 1.0
    formulation: str = "relative"
    friction: float = 1.0
    friction_limit: float | None = None
    damping: float = 0.0


@dataclass(frozen=True)
class InitialConfig:
    """Initial absolute drum rotations [rad] and rates [rad/s], bottom first.

    rotations, velocities : tuple of float  In the motion's vertical plane (the plane of
        the planar models; for the models in three dimensions, the vertical plane of
        excitation.angle)
    rotations_across, velocities_across : tuple of float  Models in three dimensions
        only: the same in the vertical plane across it (the motion's direction turned by
        +90 degrees in plan), as a history's ``rotations_across``

    Empty tuples mean zero.
    """

    rotations: tuple[float, ...] = ()
    velocities: tuple[float, ...] = ()
    rotations_across: tuple[float, ...] = ()
    velocities_across: tuple[float, ...] = ()

    @property
    def across(self) -> bool:
        """Whether a rotation or rate across the motion's plane is given (not all 0)."""
        return any(self.rotations_across) or any(self.velocities_across)


@dataclass(frozen=True)
class SecondComponentConfig:
    """An analytic second horizontal component (excitation.y) of a harmonic or a pulse,
    acting at 90 degrees counter-clockwise from the motion's direction: the same formula
    scaled by amplitude_ratio and shifted in phase by phase_deg (a_y = r A sin(omega t +
    phase + phi) for a harmonic; rbm_cli.inputs.excitation says it for each pulse).

    amplitude_ratio : float  r = the second component's multiplier over the first's [-]
    phase_deg : float  phi, its phase lead [deg]
    """

    amplitude_ratio: float
    phase_deg: float = 0.0


#: A record's files with their digests (left out of a resolved config together).
_WITH_DIGEST = {
    "file": ("file", "file_sha256"),
    "vertical": ("vertical", "vertical_sha256"),
    "file_y": ("file_y", "file_y_sha256"),
}
#: ExcitationConfig fields never in Config.resolved(): the absolute paths of the files
#: depend on where the checkout lives (the path as written and the file's digest identify
#: the record), a motion given in memory is named by the grid's records, and ``directed``
#: is derived from what was written.
_LOCAL_FIELDS = ("file_path", "vertical_path", "file_y_path", "motion", "directed")


@dataclass(frozen=True)
class FilterConfig:
    """A record's zero-phase Butterworth band-pass (excitation.processing.filter).

    low_hz, high_hz : float  Corner frequencies [Hz] of its high-pass and low-pass sides,
        0 < low_hz < high_hz < the record's Nyquist frequency
    order : int  Order n of each side (run forward and backward: the gain is squared)
    """

    low_hz: float
    high_hz: float
    order: int = 4


@dataclass(frozen=True)
class ProcessingConfig:
    """How a record is processed before it is scaled (excitation.processing).

    baseline : str  'none', 'linear' or 'quadratic': the polynomial in time removed from
        the acceleration, fitted by least squares to the record's displacement
        (rbm_cli.inputs.records.remove_baseline)
    filter : FilterConfig or None  The band-pass, applied before the baseline correction
    """

    baseline: str = "none"
    filter: FilterConfig | None = None


@dataclass(frozen=True)
class ExcitationConfig:
    """Ground motion shape; amplitude and frequency come from the grid or the CLI.

    type : str  'harmonic', 'half-sine', 'free', a pulse ('one-sine', 'cycloidal',
        'ricker', 'mavroeidis-papageorgiou') or 'record'
    duration : float  Harmonic: length of the excitation; half-sine and pulses: maximum
        simulated time; free: simulated time; record: the simulated time, set by the
        loader to the record's last sample time plus free_time (not written by the
        user) [s]
    phase : float  Phase of the harmonic [rad]
    file : str or None  Record: its file (PEER NGA .AT2 or CSV) as written in the config
    file_sha256 : str or None  Record: SHA-256 of the file's bytes (identifies the record
        in the config's hash wherever the checkout lives)
    units : str  Record: units of a CSV's accelerations, 'g' or 'm/s2' (an .AT2 is in g)
    free_time : float  Record: free motion simulated after its last sample [s]
    scale : str  Record: 'pga' (the grid's amplitude [g] is the scaled record's peak
        ground acceleration: the record is multiplied by amplitude / its own PGA) or
        'factor' (the amplitude is a plain scale factor [-])
    vertical : str or None  Record: a second file, the upward ground acceleration, as
        written (scaled by the same factor as the horizontal record)
    vertical_sha256 : str or None  Its SHA-256
    im_periods : tuple of float  Record: periods [s] of the spectral accelerations a
        domain's rows report beside the column's first elastic period (no effect on a
        run; left out of :meth:`resolved` when empty, as before the key existed)
    gamma : float or None  Mavroeidis-Papageorgiou: oscillatory character, > 1 [-]
    nu : float or None  Mavroeidis-Papageorgiou: phase of the harmonic [rad]
    file_path, vertical_path : str or None  Record: the files' absolute paths (resolved
        against the config's folder); not in :meth:`resolved`, not compared
    motion : rbm_cli.config.motions.Motion or None  Record: the motion given as arrays in
        place of a file (then ``file`` is its name and ``file_sha256`` the digest of its
        samples, which identify it); not in :meth:`resolved`, not compared
    file_y : str or None  Record: a second file, the record's horizontal component at 90
        degrees counter-clockwise from it (same formats, units and sampling; scaled by the
        same factor; models in three dimensions only)
    file_y_sha256, file_y_path : str or None  Its SHA-256 and absolute path
    angle : float  Azimuth of the horizontal motion in plan [deg], from the x axis (the
        plane the planar models rock in, where only 0 is taken): the models in three
        dimensions take any; left out of :meth:`resolved` when 0, as before the key existed
    directed : bool  excitation.angle was written (0 included): a model that moves in three
        dimensions when its motion is given a direction does so (ModelEntry.any_direction);
        never in :meth:`resolved` (Config.resolved says the dimensions instead)
    y : SecondComponentConfig or None  A harmonic's or a pulse's analytic second
        horizontal component, at 90 degrees counter-clockwise from the motion's direction
        (models in three dimensions only); left out of :meth:`resolved` when None
    processing : ProcessingConfig or None  Record: its baseline correction and band-pass,
        applied to the record (and the vertical record) before scaling; None: the record
        as read (also for a processing that changes nothing, so the config's hash is the
        one it had before processing existed)
    """

    type: str = "harmonic"
    duration: float = 10.0
    phase: float = 0.0
    initial: InitialConfig = field(default_factory=InitialConfig)
    file: str | None = None
    file_sha256: str | None = None
    units: str = "g"
    free_time: float = DEFAULT_FREE_TIME
    scale: str = "pga"
    gamma: float | None = None
    nu: float | None = None
    vertical: str | None = None
    vertical_sha256: str | None = None
    im_periods: tuple[float, ...] = ()
    file_path: str | None = field(default=None, compare=False)
    vertical_path: str | None = field(default=None, compare=False)
    motion: Any = field(default=None, compare=False)
    processing: ProcessingConfig | None = None
    angle: float = 0.0
    directed: bool = False
    file_y: str | None = None
    file_y_sha256: str | None = None
    file_y_path: str | None = field(default=None, compare=False)
    y: SecondComponentConfig | None = None

    def resolved(self) -> dict:
        """The settings that define the motion, as plain data: every field, but those of
        other excitation types (ONLY_FOR, a record's digests with their files) and the
        local ones (_LOCAL_FIELDS)."""
        out = asdict(self)
        drop = list(_LOCAL_FIELDS)
        for key, kinds in ONLY_FOR.items():
            if self.type not in kinds:
                drop += _WITH_DIGEST.get(key, (key,))
        for key in drop:
            out.pop(key)
        return out


@dataclass(frozen=True)
class Axis:
    """A grid axis over config keys (rbm_cli.config.grid): ``paths`` (one, or several
    linked) and its points, each a tuple of one value per path (numbers or strings, as
    written; ``column.size`` and ``column.slenderness`` are virtual paths)."""

    paths: tuple[str, ...]
    points: tuple[tuple, ...]


@dataclass(frozen=True)
class GridConfig:
    """Sweep grid, at the edge of the program: amplitudes in g, frequencies in Hz, and the
    axes over other config keys (outermost first; the cells are the product of all)."""

    amplitudes_g: tuple[float, ...] = ()
    frequencies_hz: tuple[float, ...] = ()
    axes: tuple[Axis, ...] = ()
    #: The record files the axes name (a suite): (key path, file as written, SHA-256 of its
    #: bytes), so that a record's content, not only its name, is in the config's hash.
    records: tuple[tuple[str, str, str], ...] = ()

    @property
    def axis_paths(self) -> tuple[str, ...]:
        """The config key paths the grid varies beside amplitude and frequency."""
        return tuple(p for axis in self.axes for p in axis.paths)

    @property
    def n_points(self) -> int:
        """Points of the axes over config keys (1 without such axes)."""
        n = 1
        for axis in self.axes:
            n *= len(axis.points)
        return n

    @property
    def n_cells(self) -> int:
        """Cells of the grid, counted without listing them: amplitudes x frequencies (one
        where the excitation has none) x the points of the other axes."""
        return len(self.amplitudes_g) * max(1, len(self.frequencies_hz)) * self.n_points


@dataclass(frozen=True)
class CollapseConfig:
    ratio: float = 1.0


#: A run's budgets when solver.max_steps / max_events are `auto` (SolverConfig.for_run): this
#: many per second of motion and per joint, and never fewer than the floor (the fixed budgets
#: of earlier versions). Measured (docs/stability.md): the paper's column in 16 drums under
#: the 30 s records rdk_01 and rdk_02 and 5 s of free motion, at 0.1 g and rtol 1e-10, takes
#: 893-935 steps and 461-478 events a second and a joint (0.26 and 0.27 million events).
BUDGET_PER_JOINT_SECOND = {"max_steps": 20_000, "max_events": 2_000}
BUDGET_FLOOR = {"max_steps": 2_000_000, "max_events": 200_000}


@dataclass(frozen=True)
class SolverConfig:
    """Integrator settings.

    method : str  'auto' (the default: the closed form where it applies, else DOP853;
        rbm_cli.models.methods.resolve_method), a
        Runge-Kutta pair of scipy.integrate.solve_ivp, 'exact' (model rbm: closed-form
        integration of the linear pieces, rbm_cli.models.rbm.exact), 'exact-first' (model
        rbm, every joint elastic: exact while every joint stays closed, else DOP853 from
        the start; rbm_cli.models.rbm.exact_first) or 'closed-form' (the rigid block's
        closed form: a rigid RBM monolith, housner-linear; rbm_cli.models.rbm.closed_form);
        the tolerances do not apply to exact and closed-form
    rtol, atol : float  Tolerances (atol relative to the rotation scale theta_u)
    max_steps : int or None  Step budget of one run; beyond it the run is 'failed'. None
        (`auto`, the default): it scales with the run (:meth:`for_run`)
    max_events : int or None  Budget of events (kinks, impacts) of one run; None (`auto`):
        it scales with the run
    time_step : float  Fixed time step of the contact engine (model bullet) [s]
    implementation : str  'compiled' (numba) or 'python' (the same source run uncompiled,
        rbm_cli.base.jit.plain: the same bits, 30-100x slower; for debugging)
    max_wall_time : float  Wall-clock budget of one run [s]; beyond it the run is
        'failed' (a guard against a run that would not end, not a tolerance)
    stop : str  When a sweep's run may end before its motion does (:data:`STOPS`):
        'figures' (the default: every figure final) or 'outcome' (model rbm, formulation
        relative: survival certain, the peaks those up to the stop)
    """

    method: str = "auto"
    rtol: float = 1e-10
    atol: float = 1e-12
    max_steps: int | None = None
    max_events: int | None = None
    time_step: float = 1e-4
    implementation: str = "compiled"
    max_wall_time: float = 3600.0
    stop: str = "figures"

    def for_run(self, duration_s: float, joints: int) -> SolverConfig:
        """These settings with the budgets of one run: a budget written stays as written;
        `auto` (None) gives BUDGET_PER_JOINT_SECOND steps or events per second of motion
        [s] and per joint (a column's joints, 1 for a block), and never fewer than
        BUDGET_FLOOR: a 16-drum column under a 35 s record gets 11.2 million steps and
        1.12 million events, a block under 10 s the floors."""
        if self.max_steps is not None and self.max_events is not None:
            return self
        scale = max(float(duration_s), 0.0) * max(int(joints), 1)
        budgets = {}
        for key in ("max_steps", "max_events"):
            written = getattr(self, key)
            scaled = math.ceil(BUDGET_PER_JOINT_SECOND[key] * scale)
            budgets[key] = written if written is not None else max(BUDGET_FLOOR[key], scaled)
        return replace(self, **budgets)


@dataclass(frozen=True)
class Config:
    """A validated config.

    The sections are typed and in SI (the grid in g and Hz); ``written`` is the mapping the
    user wrote (YAML or a dict), kept as given once it validated, so that a stored result
    (meta.json) can be re-read exactly as it was configured, never rebuilt from derived
    values. It takes no part in equality, in the config's hash or in :meth:`resolved`;
    nor does ``base_dir``, the folder relative paths in it (a record's file) were taken
    from (the config file's folder, or the current directory of the time it was parsed),
    so that ``written`` can be validated again as it was:
    ``parse_config(config.written, base_dir=config.base_dir)``.

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5}})
    >>> cfg.column.height, cfg.column.density  # [m], [kg/m^3]
    (2.0, 2700.0)
    """

    name: str
    column: ColumnConfig
    model: str = "rbm"
    interface: InterfaceConfig = field(default_factory=InterfaceConfig)
    excitation: ExcitationConfig = field(default_factory=ExcitationConfig)
    grid: GridConfig = field(default_factory=GridConfig)
    collapse: CollapseConfig = field(default_factory=CollapseConfig)
    solver: SolverConfig = field(default_factory=SolverConfig)
    #: Config keys drawn from distributions, a sample per cell (rbm_cli.config.uncertain).
    uncertain: UncertainConfig | None = None
    #: Columns under a beam (a rocking frame): None for a column standing alone.
    frame: FrameConfig | None = None
    written: dict | None = field(default=None, compare=False, repr=False)
    base_dir: str | None = field(default=None, compare=False, repr=False)

    def resolved(self) -> dict:
        """Every resolved setting as plain data: dataclasses.asdict without ``written`` and
        ``base_dir``, the excitation's fields that apply (:meth:`ExcitationConfig.resolved`)
        and ``dimensions``: 3 where the model moves in three dimensions (:attr:`three_d`),
        else 2. A config's hash is taken of it (rbm_cli.study.fingerprint)."""
        out = asdict(self)
        out.pop("written", None)
        out.pop("base_dir", None)
        out["excitation"] = self.excitation.resolved()
        out["dimensions"] = 3 if self.three_d else 2
        return out

    @property
    def three_d(self) -> bool:
        """Whether the model moves in three dimensions: always for a model in three
        dimensions (ModelEntry.three_d); for a model that takes any direction
        (ModelEntry.any_direction), when the motion is given a direction
        (``excitation.angle`` written, 0 included, or an axis over it) or a second
        horizontal component (``excitation.file_y`` or ``excitation.y``, or an axis over
        either: a suite of pairs)."""
        entry = MODELS[self.model]
        if entry.three_d:
            return True
        if not entry.any_direction:
            return False
        e = self.excitation
        paths = self.grid.axis_paths
        return (
            e.directed
            or e.angle != 0.0
            or e.file_y is not None
            or e.y is not None
            or "excitation.angle" in paths
            or "excitation.file_y" in paths
            or any(p == "excitation.y" or p.startswith("excitation.y.") for p in paths)
        )

    def record_files(self) -> tuple[tuple[str, str, str], ...]:
        """Every record file the config names, by content: (key path, file as written,
        SHA-256), the excitation's own (``excitation.file``, ``excitation.vertical``) then
        those of the grid's axes."""
        e = self.excitation
        own = tuple(
            (f"excitation.{key}", written, digest)
            for key, written, digest in (
                ("file", e.file, e.file_sha256),
                ("vertical", e.vertical, e.vertical_sha256),
                ("file_y", e.file_y, e.file_y_sha256),
            )
            if e.type == "record" and written is not None and digest is not None
        )
        return own + tuple(r for r in self.grid.records if r not in own)
