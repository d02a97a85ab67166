"""The row of a study: one cell's run as a domain reports it (RunResult, made from a
model's Outcome by rbm_cli.study.simulate), and the columns of domain.csv."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import MODELS
from rbm_cli.models.history import History
from rbm_cli.study.schema import COMMON_RESULT_COLUMNS, RESIDUAL_COLUMNS, C

STATUSES = ("collapsed", "survived", "failed")

#: The result's columns every domain.csv has, in order (rbm_cli.study.schema).
CSV_FIELDS = COMMON_RESULT_COLUMNS
#: The column a domain of model rbm with interface.friction given adds after
#: friction_demand: 1 where the demand exceeds the coefficient, else 0.
SLIDES_FIELD = C.slides
#: The columns a domain of a model in three dimensions adds after max_top_displacement_m:
#: the azimuth its lean pointed to at collapse [deg from x, in (-180, 180]; empty if it
#: survived], and the angle its lean's direction swept while it rolled [turns].
THREE_D_FIELDS = (C.collapse_azimuth_deg, C.wobble_turns)
#: The columns a domain of the contact engine (model bullet) adds after those: the
#: residual slip [m], the top's residual offset [m] and the residual tilt ratio [-] where a
#: run that survived ended (empty if it collapsed or failed).
RESIDUAL_FIELDS = RESIDUAL_COLUMNS


@dataclass(frozen=True)
class RunResult:
    """Outcome of one run.

    status : str  'collapsed', 'survived' or 'failed'
    t_collapse_s : float  Time of collapse [s] (nan if none)
    collapse_interface : int or None  1-based interface that reached its limit
    max_rotation_ratio : float  max over interfaces and time of the collapse
        quantity over its limit
    max_top_displacement_m : float  max |u_{n+1} - u_1| [m]
    n_uplifts : int  Rest-to-motion transitions (rigid law) or excursions
        beyond an interface's elastic branch (finite K_M)
    n_impacts : int  Zero crossings of a law argument after an excursion
        beyond its elastic branch (every crossing for a rigid law)
    n_steps, n_rhs : int  Accepted integrator steps, right-hand-side evaluations
    friction_demand : tuple of float  The largest |T_i / N_i| held in one direction for
        friction_duration_s, per interface (domain.csv keeps their largest, for models rbm
        and rbm-3d; empty for the models that do not compute it or, as bullet's contacts,
        slide for real: their |T / N| is capped by Coulomb)
    friction_demand_peak : tuple of float  Its instantaneous peak, max over time of
        |T_i / N_i| per interface (the joints' elastic phases and the drums' rattles
        included; empty where not computed; not in domain.csv)
    friction_duration_s : float or None  The duration friction_demand is held for [s] for
        a model with the RBM's joints (models.rbm.pieces.FRICTION_DURATION), None for the
        others
    wall_time_s : float  Wall time of the run [s]
    method : str  The method that ran (solver.method, `auto` resolved; not in domain.csv)
    model : str  The model that ran (config.model)
    friction_limit : float or None  The friction coefficient the demand was checked
        against (interface.friction of model rbm), None: not checked
    slip : (t [s], interface) or None  Where the demand first exceeded friction_limit
        (interface from 1, at the ground); None: it did not, or no check
    collapse_azimuth_deg : float  Model in three dimensions: where its lean pointed at
        collapse [deg] (nan: no collapse, or a planar model)
    wobble_turns : float  Model in three dimensions: the angle its lean's direction swept
        while it rolled [turns] (nan for a planar model)
    three_d : bool  The run moved in three dimensions (Config.three_d): domain.csv keeps
        the collapse azimuth and the wobbling turns
    residual_slip_m : float  The contact engine's residual slip: the largest |slip| of a
        joint where the run ended [m] (the motion and its free time over, or at rest after
        the pulse; nan if it collapsed or failed, and for the other models)
    residual_top_offset_m : float  The top's offset in plan from its start there [m]
    residual_tilt_ratio : float  The largest |relative rotation| / alpha_i of a joint
        there [-]
    residual : bool  The model gives the residual state (MODELS' ``residual``):
        domain.csv keeps the three
    energy : dict or None  A recorded run's energy account [J] (models.outcome.EnergyAccount
        as_dict: start, end, the ground's work, what damping and impacts took, the residual
        of the balance); None where the method keeps none (not in domain.csv)
    """

    status: str
    amplitude_g: float
    frequency_hz: float | None  # None: a record (no frequency)
    t_collapse_s: float
    collapse_interface: int | None
    max_rotation_ratio: float
    max_top_displacement_m: float
    n_uplifts: int
    n_impacts: int
    n_steps: int
    n_rhs: int
    message: str
    friction_demand: tuple[float, ...]
    wall_time_s: float
    history: History | None = None
    method: str = ""
    model: str = "rbm"
    friction_limit: float | None = None
    slip: tuple[float, int] | None = None
    energy: dict | None = None
    collapse_azimuth_deg: float = float("nan")
    wobble_turns: float = float("nan")
    three_d: bool = False
    friction_demand_peak: tuple[float, ...] = ()
    friction_duration_s: float | None = None
    residual_slip_m: float = float("nan")
    residual_top_offset_m: float = float("nan")
    residual_tilt_ratio: float = float("nan")
    residual: bool = False

    @property
    def collapsed(self) -> bool:
        return self.status == "collapsed"

    @property
    def max_friction_demand(self) -> float:
        finite = [v for v in self.friction_demand if np.isfinite(v)]
        return max(finite) if finite else float("nan")

    @property
    def max_friction_demand_peak(self) -> float:
        finite = [v for v in self.friction_demand_peak if np.isfinite(v)]
        return max(finite) if finite else float("nan")

    @property
    def domain_friction_demand(self) -> float:
        """domain.csv's friction_demand: max_friction_demand for model rbm, else NaN (not
        computed, or a contact engine's friction, capped by Coulomb, not a demand)."""
        return self.max_friction_demand if MODELS[self.model].beam else float("nan")

    @property
    def slides(self) -> int | None:
        """1 where the friction demand exceeds friction_limit, 0 where not, None without a
        limit or a demand (a failed run)."""
        demand = self.domain_friction_demand
        if self.friction_limit is None or not np.isfinite(demand):
            return None
        return int(demand > self.friction_limit)

    def row(self) -> dict:
        """The domain.csv fields, in CSV_FIELDS order (collapsed as 0/1), and ``slides``
        when the demand was checked against a friction coefficient."""
        out = {k: getattr(self, k) for k in CSV_FIELDS}
        out[C.collapsed] = int(self.collapsed)
        out[C.friction_demand] = self.domain_friction_demand
        if self.friction_limit is not None:
            out[SLIDES_FIELD] = self.slides
        if self.three_d:
            out.update({k: getattr(self, k) for k in THREE_D_FIELDS})
        if self.residual:
            out.update({k: getattr(self, k) for k in RESIDUAL_FIELDS})
        return out

    def summary(self) -> dict:
        """The domain.csv fields plus friction demand per interface (for a model with the
        RBM's joints also the duration it is held for and its instantaneous peak), the first
        exceedance of the friction coefficient (when checked) and wall time (JSON-ready)."""
        out = self.row()
        out[C.friction_demand] = [v if np.isfinite(v) else None for v in self.friction_demand]
        out["max_friction_demand"] = self.max_friction_demand
        if self.friction_duration_s is not None:
            out["friction_duration_s"] = self.friction_duration_s
            out["friction_demand_peak"] = [v if np.isfinite(v) else None
                                           for v in self.friction_demand_peak]  # fmt: skip
            out["max_friction_demand_peak"] = self.max_friction_demand_peak
        if self.friction_limit is not None:
            out["friction_limit"] = self.friction_limit
            out["slip_interface"] = None if self.slip is None else self.slip[1]
            out["t_slip_s"] = None if self.slip is None else self.slip[0]
        out["wall_time_s"] = self.wall_time_s
        out["method"] = self.method
        if self.energy is not None:
            out["energy"] = dict(self.energy)
        for k, v in out.items():
            if isinstance(v, float) and not np.isfinite(v):
                out[k] = None
        return out
