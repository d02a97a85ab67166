"""The ``uncertain`` section: config keys drawn from distributions, a Latin hypercube of
samples per grid cell.

A study of a real column does not know its joint stiffness, its restitution or its drums'
sizes exactly. ``uncertain`` names numeric config keys by their dotted path and gives each a
distribution; a sweep runs every cell of the grid once per sample (rbm_cli.config.points:
each sample of each point is a config of its own, validated as a config written by hand)::

    uncertain:
      samples: 16          # per cell of the grid
      seed: 1
      keys:
        interface.stiffness.normal: {lognormal: {median: 5.0e9, beta: 0.4}}
        interface.restitution: {uniform: [0.85, 0.95]}

Distributions (scipy.stats; one of each per key):

- ``lognormal: {median, beta}``: ln X normal with mean ln(median) and standard deviation
  beta (scipy.stats.lognorm(s=beta, scale=median)); beta 0 is the median alone;
- ``normal: {mean, std, bounds: [lo, hi]}``: normal, truncated to the bounds when given
  (scipy.stats.norm, scipy.stats.truncnorm); std 0 is the mean alone;
- ``truncnorm: {mean, std, bounds: [lo, hi]}``: the normal truncated to the bounds (needed);
- ``uniform: [lo, hi]``: uniform on [lo, hi] (equal bounds: that value alone).

The design (:func:`draw`) is scipy.stats.qmc.LatinHypercube over the keys (one dimension
per key, ``seed`` its generator's seed: the same seed gives the same design), each column of
it mapped through its key's inverse CDF (ppf): every one of the ``samples`` equal-probability
strata of every key holds exactly one sample. The probabilities are kept within
[U_MIN, 1 - U_MIN] (2^-53: 8.2 standard deviations of a normal), and the values are rounded
to 12 significant digits, as domain.csv writes them, so the value a row shows is the value
its run used.

A distribution must draw only values its key takes: :func:`probe_values` gives the least
and the largest value the design can draw (the ppf at U_MIN and 1 - U_MIN), and the loader
sets each in turn in the config and validates it as a config (rbm_cli.config.load), so a
normal without bounds on a stiffness that must be > 0 is refused when the config is loaded,
not as a failed run. Which columns domain.csv gets: ``sample`` and one per key, named
``uncertain.<key>`` (:func:`column_name`; rbm_cli.study.schema).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.validate import describe, fmt, integer, is_number, join, mapping

#: The keys of the section.
UNCERTAIN_KEYS = ("samples", "seed", "keys")
#: The distributions and the keys of each (uniform is a list [lo, hi]).
DISTRIBUTIONS = {
    "lognormal": ("median", "beta"),
    "normal": ("mean", "std", "bounds"),
    "truncnorm": ("mean", "std", "bounds"),
    "uniform": ("lo", "hi"),
}
#: The most samples per cell (each sample of each point of the grid is a config of its own).
MAX_SAMPLES = 10_000
#: The probabilities of a draw are kept in [U_MIN, 1 - U_MIN] (the extremes probed).
U_MIN = 2.0**-53
#: Significant digits of a drawn value (domain.csv's).
DIGITS = 12
#: domain.csv's column of a row's sample number (0, 1, ...), and the prefix of a key's.
SAMPLE = "sample"
PREFIX = "uncertain."
#: Paths that cannot be uncertain: the folder's name, the model, the grid, this section.
FIXED = ("name", "model", "grid", "uncertain")


@dataclass(frozen=True)
class Distribution:
    """One key's distribution: its name (:data:`DISTRIBUTIONS`) and parameters, in the
    order of :data:`DISTRIBUTIONS` (``bounds`` as (lo, hi) or None)."""

    name: str
    params: tuple

    def as_dict(self) -> dict:
        """The distribution as written (a mapping of its parameters; uniform a list)."""
        if self.name == "uniform":
            return {"uniform": list(self.params)}
        keys = DISTRIBUTIONS[self.name]
        pairs = zip(keys, self.params, strict=True)
        out = {k: (list(v) if isinstance(v, tuple) else v) for k, v in pairs}
        return {self.name: {k: v for k, v in out.items() if v is not None}}

    @property
    def text(self) -> str:
        """The distribution in a message: ``normal(mean=5e+09, std=4e+09)``."""
        if self.name == "uniform":
            return f"uniform({fmt(self.params[0])}, {fmt(self.params[1])})"
        keys = DISTRIBUTIONS[self.name]
        parts = [
            f"{k}=[{fmt(v[0])}, {fmt(v[1])}]" if isinstance(v, tuple) else f"{k}={fmt(v)}"
            for k, v in zip(keys, self.params, strict=True)
            if v is not None
        ]
        return f"{self.name}({', '.join(parts)})"

    @property
    def point_mass(self) -> float | None:
        """The value of a distribution that draws one value only (beta 0, std 0, equal
        bounds), None for another."""
        if self.name == "lognormal":
            median, beta = self.params
            return median if beta == 0 else None
        if self.name == "uniform":
            lo, hi = self.params
            return lo if lo == hi else None
        mean, std, bounds = self.params
        if bounds is not None and bounds[0] == bounds[1]:
            return bounds[0]
        return mean if std == 0 else None

    def ppf(self, u):
        """The inverse CDF at probabilities ``u`` (scipy.stats, imported here)."""
        # lazy: scipy.stats loads only where needed (docs/architecture.md, Start-up)
        import numpy as np
        from scipy import stats

        u = np.asarray(u, dtype=float)
        fixed = self.point_mass
        if fixed is not None:
            return np.full(u.shape, float(fixed))
        return self.frozen(stats).ppf(u)

    def frozen(self, stats):
        """The scipy.stats frozen distribution (not for a point mass)."""
        if self.name == "lognormal":
            median, beta = self.params
            return stats.lognorm(s=beta, scale=median)
        if self.name == "uniform":
            lo, hi = self.params
            return stats.uniform(loc=lo, scale=hi - lo)
        mean, std, bounds = self.params
        if bounds is None:
            return stats.norm(loc=mean, scale=std)
        lo, hi = bounds
        return stats.truncnorm((lo - mean) / std, (hi - mean) / std, loc=mean, scale=std)

    def cdf(self, x):
        """The CDF at ``x`` (scipy.stats; a point mass: 0 below its value, 1 from it)."""
        # lazy: scipy.stats loads only where needed (docs/architecture.md, Start-up)
        import numpy as np
        from scipy import stats

        fixed = self.point_mass
        if fixed is not None:
            return (np.asarray(x, dtype=float) >= fixed).astype(float)
        return self.frozen(stats).cdf(x)


@dataclass(frozen=True)
class UncertainConfig:
    """The validated ``uncertain`` section (module docstring).

    samples : int  Samples per cell of the grid
    seed : int  The Latin hypercube's seed
    keys : tuple of (str, Distribution)  The dotted paths and their distributions, as written
    values : tuple of tuple of float  The design: per sample, one value per key, in key order
    """

    samples: int
    seed: int
    keys: tuple[tuple[str, Distribution], ...]
    values: tuple[tuple[float, ...], ...] = ()

    @property
    def paths(self) -> tuple[str, ...]:
        return tuple(p for p, _ in self.keys)

    @property
    def columns(self) -> tuple[str, ...]:
        """domain.csv's columns of a sample: ``sample``, then one per key."""
        return (SAMPLE, *(column_name(p) for p in self.paths))

    def point(self, sample: int) -> tuple[tuple[str, Any], ...]:
        """A sample's (column, value) pairs: its number, then its value of each key."""
        values = self.values[sample]
        return ((SAMPLE, sample), *zip((column_name(p) for p in self.paths), values, strict=True))

    def design(self) -> dict:
        """The design as plain data (meta.json's ``uncertain``)."""
        return {
            "samples": self.samples,
            "seed": self.seed,
            "method": "scipy.stats.qmc.LatinHypercube, each key's ppf",
            "keys": {p: d.as_dict() for p, d in self.keys},
            "columns": list(self.columns),
            "values": [list(v) for v in self.values],
        }


def column_name(path: str) -> str:
    """domain.csv's column of a key's drawn value: ``uncertain.<path>``."""
    return PREFIX + path


def is_sample_column(name: str) -> bool:
    """Whether a column of a domain is a sample's (``sample``, ``uncertain.<path>``)."""
    return name == SAMPLE or str(name).startswith(PREFIX)


def config_path(column: str) -> str | None:
    """The config key a sample's column sets (None for ``sample``, which sets none)."""
    return column[len(PREFIX) :] if column.startswith(PREFIX) else None


def _real(value: Any, where: str) -> float:
    if not is_number(value) or not math.isfinite(float(value)):
        raise ConfigError(f"{where} must be a finite number, got {describe(value)}")
    return float(value)


def _bounds(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(f"{where} must be a list [lo, hi], got {describe(value)}")
    lo, hi = (_real(v, join(where, i)) for i, v in enumerate(value))
    if lo > hi:
        raise ConfigError(f"{where} must have lo <= hi, got [{fmt(lo)}, {fmt(hi)}]")
    return lo, hi


def parse_distribution(raw: Any, where: str) -> Distribution:
    """One key's distribution: a mapping of one name (:data:`DISTRIBUTIONS`) to its
    parameters; one line naming the key otherwise."""
    names = ", ".join(DISTRIBUTIONS)
    if not isinstance(raw, Mapping) or len(raw) != 1:
        raise ConfigError(
            f"{where} must be one distribution ({names}), e.g. {{uniform: [0.85, 0.95]}},"
            f" got {describe(raw)}"
        )
    ((name, params),) = raw.items()
    if name not in DISTRIBUTIONS:
        raise ConfigError(f"{where}: unknown distribution {str(name)!r} (allowed: {names})")
    at = join(where, name)
    if name == "uniform":
        return Distribution(name, _bounds(params, at))
    needed = ("median", "beta") if name == "lognormal" else ("mean", "std")
    if name == "truncnorm":
        needed += ("bounds",)
    p = mapping(params, at, DISTRIBUTIONS[name], needed)
    if name == "lognormal":
        median, beta = _real(p["median"], join(at, "median")), _real(p["beta"], join(at, "beta"))
        if median <= 0:
            raise ConfigError(f"{join(at, 'median')} must be > 0, got {fmt(median)}")
        if beta < 0:
            raise ConfigError(f"{join(at, 'beta')} must be >= 0, got {fmt(beta)}")
        return Distribution(name, (median, beta))
    mean, std = _real(p["mean"], join(at, "mean")), _real(p["std"], join(at, "std"))
    if std < 0:
        raise ConfigError(f"{join(at, 'std')} must be >= 0, got {fmt(std)}")
    bounds = _bounds(p["bounds"], join(at, "bounds")) if "bounds" in p else None
    if bounds is not None and not bounds[0] <= mean <= bounds[1] and std == 0:
        raise ConfigError(
            f"{at}: std 0 draws the mean {fmt(mean)}, outside bounds"
            f" [{fmt(bounds[0])}, {fmt(bounds[1])}]"
        )
    return Distribution(name, (mean, std, bounds))


def parse_uncertain(
    raw: Any, grid_paths: tuple[str, ...], n_points: int, max_points: int
) -> UncertainConfig:
    """The validated section without its design (``values``: :func:`with_design`); the keys'
    values are checked by the loader (:func:`probe_values`), which refuses a path that is not
    a key of the config. ``grid_paths``: the grid's axes (a key cannot be both),
    ``n_points``: its points (samples x points at most ``max_points``)."""
    u = mapping(raw, "uncertain", UNCERTAIN_KEYS, ("samples", "keys"))
    samples = integer(u["samples"], "uncertain.samples", 1, MAX_SAMPLES)
    seed = integer(u.get("seed", 0), "uncertain.seed", 0, 2**32 - 1)
    if samples * n_points > max_points:
        raise ConfigError(
            f"uncertain.samples: {samples} samples x {n_points:,} points of the grid's axes"
            f" make {samples * n_points:,} configs (at most {max_points:,})"
        )
    keys = u["keys"]
    if not isinstance(keys, Mapping) or not keys:
        raise ConfigError(
            "uncertain.keys must be a mapping of config key paths to distributions, e.g."
            f" {{interface.restitution: {{uniform: [0.85, 0.95]}}}}, got {describe(keys)}"
        )
    out = []
    for path, dist in keys.items():
        where = f"uncertain.keys.{path}"
        if not isinstance(path, str) or not all(path.split(".")):
            raise ConfigError(
                f"uncertain.keys: a key is a config key by its dotted path"
                f" (interface.restitution, column.height, ...), got {describe(path)}"
            )
        if path.split(".")[0] in FIXED:
            raise ConfigError(f"{where}: {path.split('.')[0]} cannot be uncertain")
        if path in grid_paths:
            raise ConfigError(f"{where}: {path} is an axis of the grid too: use one")
        out.append((path, parse_distribution(dist, where)))
    return UncertainConfig(samples, seed, tuple(out))


def draw(uncertain: UncertainConfig):
    """The design: a (samples x keys) array, the Latin hypercube of the keys' probabilities
    (scipy.stats.qmc.LatinHypercube, seeded) through each key's ppf, rounded to DIGITS
    significant digits (module docstring)."""
    # lazy: scipy.stats loads only where needed (docs/architecture.md, Start-up)
    import numpy as np
    from scipy.stats import qmc

    sampler = qmc.LatinHypercube(d=len(uncertain.keys), rng=np.random.default_rng(uncertain.seed))
    u = np.clip(sampler.random(uncertain.samples), U_MIN, 1.0 - U_MIN)
    columns = [d.ppf(u[:, j]) for j, (_, d) in enumerate(uncertain.keys)]
    return np.array([[_rounded(x) for x in col] for col in columns]).T.reshape(
        uncertain.samples, len(uncertain.keys)
    )


def _rounded(x: float) -> float:
    return float(f"{float(x):.{DIGITS}g}")


def with_design(uncertain: UncertainConfig) -> UncertainConfig:
    """The section with its design's values (:func:`draw`)."""
    values = tuple(tuple(float(v) for v in row) for row in draw(uncertain))
    return UncertainConfig(uncertain.samples, uncertain.seed, uncertain.keys, values)


def probe_values(distribution: Distribution) -> tuple[float, ...]:
    """The median, the least and the largest value the design can draw of a distribution
    (its ppf at 1/2, U_MIN and 1 - U_MIN, rounded as drawn; a point mass: its value)."""
    fixed = distribution.point_mass
    if fixed is not None:
        return (float(fixed),)
    return tuple(dict.fromkeys(_rounded(x) for x in distribution.ppf([0.5, U_MIN, 1.0 - U_MIN])))


__all__ = [
    "DISTRIBUTIONS",
    "MAX_SAMPLES",
    "PREFIX",
    "SAMPLE",
    "U_MIN",
    "Distribution",
    "UncertainConfig",
    "column_name",
    "config_path",
    "draw",
    "is_sample_column",
    "parse_distribution",
    "parse_uncertain",
    "probe_values",
    "with_design",
]
