"""A seeded suite of synthetic ground motions: the stochastic model of Rezaeian and Der
Kiureghian (2010), reproducible bit for bit from its seed on any machine.

The model (RDK 2008, 2010; modulated, filtered white noise with a time-varying filter, then
high-passed) is :mod:`rbm_cli.inputs.rdk_model`; its names are re-exported here. The suite
draws each record's parameters from stated ranges (:data:`PARAMETER_RANGES`; these are our
choice, a moderate shallow crustal earthquake on firm ground, not RDK's regression on
magnitude and distance) and scales each record to a drawn peak ground acceleration.

Bit for bit: the model's arithmetic is portable (see :mod:`rbm_cli.inputs.rdk_model`), the
normal draws come from :mod:`rbm_cli.base.portable_math`, and each record has its own
generator spawned from the seed, so the suite is the same bytes on every machine.

References
----------
.. [1] S. Rezaeian and A. Der Kiureghian (2010). Simulation of synthetic ground motions for
   specified earthquake and site characteristics. Earthquake Engineering and Structural
   Dynamics 39(10), 1155-1180.
"""

from __future__ import annotations

import os
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np

from rbm_cli.base import portable_math as pm
from rbm_cli.base.errors import RbmError
from rbm_cli.inputs.rdk_model import (
    FLOOR_HZ,
    HIGHPASS_HZ,
    RDKParameters,
    filter_frequency_hz,
    highpass,
    impulse_responses,
    modulating_function,
    modulating_parameters,
    unit_process,
)
from rbm_cli.inputs.records import G, Record, write_at2

#: Seed of the shipped suite (``configs/records/synthetic/``).
SEED = 17

#: Records, duration [s] and time step [s] of the shipped suite.
SUITE_SIZE, SUITE_DURATION_S, SUITE_DT_S = 20, 30.0, 0.01

#: Ranges of the uniformly drawn parameters of the suite (our choice), one per field of
#: :class:`RDKParameters`.
PARAMETER_RANGES = {
    "duration_5_95_s": (5.0, 10.0),
    "t_mid_s": (4.0, 8.0),
    "frequency_mid_hz": (2.0, 6.0),
    "frequency_slope_hz_per_s": (-0.08, 0.0),
    "damping": (0.1, 0.5),
    "pga_g": (0.2, 0.5),
}

# --------------------------------------------------------------------------- records


def simulate(
    params: RDKParameters,
    rng: np.random.Generator,
    duration_s: float = SUITE_DURATION_S,
    dt: float = SUITE_DT_S,
    name: str = "rdk",
) -> Record:
    """One synthetic record of the RDK model, high-passed and scaled to ``params.pga_g``.

    Parameters
    ----------
    params : RDKParameters
        Model parameters
    rng : numpy.random.Generator
        Source of the white noise (its state advances)
    duration_s : float
        Record length [s]; the record has round(duration_s / dt) + 1 samples from t = 0
    dt : float
        Time step [s]
    name : str
        Record name

    Returns
    -------
    Record
        Acceleration [m/s^2] with max |a| = pga_g g

    Examples
    --------
    >>> p = RDKParameters(10.0, 6.0, 4.0, -0.05, 0.3, 0.3)
    >>> rec = simulate(p, np.random.default_rng(1), duration_s=20.0)
    >>> round(rec.pga / G, 12), len(rec)
    (0.3, 2001)
    """
    if not (dt > 0.0 and duration_s > dt):
        raise RbmError(f"synthetic: need 0 < dt < duration_s, got dt={dt}, duration_s={duration_s}")
    n = int(round(duration_s / dt)) + 1
    alpha_2, alpha_3 = modulating_parameters(params.duration_5_95_s, params.t_mid_s)
    t = np.arange(n) * dt
    z = unit_process(params, n, dt, pm.standard_normal(rng, n))
    a = highpass(modulating_function(t, alpha_2, alpha_3) * z, dt)
    a = a * (params.pga_g * G / float(np.max(np.abs(a))))
    title = "Rezaeian-Der Kiureghian (2010) synthetic: " + ", ".join(
        f"{k}={v!r}" for k, v in asdict(params).items()
    )
    return Record(t, a, name=name, source="rbm_cli.synthetic", title=title)


def sample_parameters(rng: np.random.Generator) -> RDKParameters:
    """Parameters drawn uniformly from :data:`PARAMETER_RANGES`, 4 significant digits."""
    values = {}
    for key, (lo, hi) in PARAMETER_RANGES.items():
        values[key] = float(f"{lo + (hi - lo) * float(rng.random()):.4g}")
    return RDKParameters(**values)


def make_suite(
    n: int = SUITE_SIZE,
    seed: int = SEED,
    duration_s: float = SUITE_DURATION_S,
    dt: float = SUITE_DT_S,
) -> list[Record]:
    """The seeded suite: ``n`` records ``rdk_01``, ``rdk_02``, ... of the RDK model.

    Record k uses its own generator, ``np.random.SeedSequence(seed).spawn(n)[k]``: first
    its parameters (:func:`sample_parameters`), then its white noise. So the first records
    of a larger suite are the records of a smaller one, and the suite is the same bits on
    every machine for a given seed.

    Examples
    --------
    >>> suite = make_suite(2, seed=17, duration_s=10.0)
    >>> [r.name for r in suite]
    ['rdk_01', 'rdk_02']
    """
    return [rec for _, rec in _suite(n, seed, duration_s, dt)]


def _suite(n: int, seed: int, duration_s: float, dt: float) -> list[tuple[RDKParameters, Record]]:
    if n < 1:
        raise RbmError(f"synthetic: n must be >= 1, got {n}")
    out = []
    for k, child in enumerate(np.random.SeedSequence(seed).spawn(n)):
        rng = np.random.Generator(np.random.PCG64(child))
        params = sample_parameters(rng)
        out.append((params, simulate(params, rng, duration_s, dt, name=f"rdk_{k + 1:02d}")))
    return out


def write_suite(
    folder: str | os.PathLike,
    n: int = SUITE_SIZE,
    seed: int = SEED,
    duration_s: float = SUITE_DURATION_S,
    dt: float = SUITE_DT_S,
) -> list[Path]:
    """Write :func:`make_suite` as ``<name>.AT2`` files and ``suite.csv`` (the parameters).

    Returns the paths written. The files are the same bytes on every machine for the same
    arguments (``configs/records/synthetic/`` is ``write_suite(that folder)``).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    rows = ["name,seed," + ",".join(PARAMETER_RANGES) + ",alpha_2,alpha_3,npts,dt_s"]
    for params, rec in _suite(n, seed, duration_s, dt):
        paths.append(write_at2(folder / f"{rec.name}.AT2", rec))
        a2, a3 = modulating_parameters(params.duration_5_95_s, params.t_mid_s)
        values = ",".join(repr(getattr(params, k)) for k in PARAMETER_RANGES)
        rows.append(f"{rec.name},{seed},{values},{a2!r},{a3!r},{len(rec)},{dt!r}")
    table = folder / "suite.csv"
    table.write_text("\n".join(rows) + "\n", encoding="utf-8", newline="\n")
    return [*paths, table]


def main(argv: list[str] | None = None) -> int:
    """``python -m rbm_cli.inputs.synthetic FOLDER [N [SEED]]``: write the suite into FOLDER."""
    args = sys.argv[1:] if argv is None else argv
    if not 1 <= len(args) <= 3:
        print("usage: python -m rbm_cli.inputs.synthetic FOLDER [N [SEED]]", file=sys.stderr)
        return 2
    n = int(args[1]) if len(args) > 1 else SUITE_SIZE
    seed = int(args[2]) if len(args) > 2 else SEED
    for path in write_suite(args[0], n, seed):
        print(path)
    return 0


__all__ = [
    "FLOOR_HZ",
    "HIGHPASS_HZ",
    "PARAMETER_RANGES",
    "SEED",
    "SUITE_DT_S",
    "SUITE_DURATION_S",
    "SUITE_SIZE",
    "RDKParameters",
    "filter_frequency_hz",
    "highpass",
    "impulse_responses",
    "main",
    "make_suite",
    "modulating_function",
    "modulating_parameters",
    "sample_parameters",
    "simulate",
    "unit_process",
    "write_suite",
]


if __name__ == "__main__":
    sys.exit(main())
