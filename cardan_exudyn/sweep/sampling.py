"""Random samples of a sweep: one parameter's distribution, and N reproducible samples of several
(independent uniform draws or a Latin hypercube, through each inverse distribution function).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from cardan_exudyn.sweep.checks import MAX_CASES, SweepError, finite_number

__all__ = ["DISTRIBUTIONS", "SAMPLING_METHODS", "Distribution", "RandomSpec"]

SAMPLING_METHODS = ("random", "lhs")
"""Independent uniform draws, or a Latin hypercube."""
DISTRIBUTIONS = {"uniform": ("low", "high"), "loguniform": ("low", "high"),
                 "normal": ("mean", "std", "low", "high")}
"""Each distribution's parameters (for ``normal``, ``low`` and ``high`` truncate it)."""


@dataclass(frozen=True)
class Distribution:
    """Distribution of one random parameter.

    Attributes
    ----------
    dist : {"uniform", "loguniform", "normal"}
        ``uniform`` on [low, high); ``loguniform`` on [low, high), 0 < low; ``normal``: mean and
        std, optionally truncated to [low, high] (either bound alone).
    low, high, mean, std : float or None
        In the parameter's unit (that of its scene path, e.g. deg for ``..._deg``).
    """

    dist: str
    low: float | None = None
    high: float | None = None
    mean: float | None = None
    std: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.dist, str) or self.dist not in DISTRIBUTIONS:
            raise SweepError(f"`dist` must be one of {sorted(DISTRIBUTIONS)}, got {self.dist!r}")
        self._set_parameters()
        self._check_ranges()

    def _set_parameters(self) -> None:
        """The given parameters as floats; SweepError for one not taken or one needed and missing."""
        allowed = DISTRIBUTIONS[self.dist]
        for name in ("low", "high", "mean", "std"):
            value = getattr(self, name)
            if value is not None:
                if name not in allowed:
                    raise SweepError(f"`{name}` is not a parameter of {self.dist!r}; give {allowed}")
                object.__setattr__(self, name, finite_number(f"`{name}`", value))
        required = ("mean", "std") if self.dist == "normal" else ("low", "high")
        missing = [n for n in required if getattr(self, n) is None]
        if missing:
            raise SweepError(f"{self.dist!r} needs {list(required)}, missing {missing}")

    def _check_ranges(self) -> None:
        """SweepError for a non-positive ``std`` or log-uniform ``low``, ``low >= high``, or a truncated
        normal with no probability between its bounds.
        """
        if self.std is not None and self.std <= 0.0:
            raise SweepError(f"`std` must be positive, got {self.std!r}")
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise SweepError(f"`low` must be below `high`, got low = {self.low!r}, high = {self.high!r}")
        if self.dist == "loguniform" and self.low <= 0.0:
            raise SweepError(f"`low` of 'loguniform' must be positive, got {self.low!r}")
        if self.dist == "normal" and self._truncated() and self._mass() < 1e-12:
            raise SweepError(f"normal(mean = {self.mean!r}, std = {self.std!r}) has no probability in "
                             f"[{self.low!r}, {self.high!r}]")

    def _truncated(self) -> bool:
        """Whether a normal distribution is cut to [low, high]."""
        return self.low is not None or self.high is not None

    def _bounds(self) -> tuple[float, float]:
        """Truncation bounds in standard deviations from the mean."""
        lo = -math.inf if self.low is None else (self.low - self.mean) / self.std
        hi = math.inf if self.high is None else (self.high - self.mean) / self.std
        return lo, hi

    def _mass(self) -> float:
        """Probability of the untruncated normal between the bounds [-]."""
        from scipy.special import ndtr  # scipy loads only for a normal distribution

        lo, hi = self._bounds()
        return float(ndtr(hi) - ndtr(lo))

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Inverse distribution function: values (the parameter's unit) at probabilities ``u`` in [0, 1)."""
        u = np.clip(np.asarray(u, dtype=float), np.finfo(float).tiny, 1.0 - np.finfo(float).epsneg)
        if self.dist == "uniform":
            return self.low + u * (self.high - self.low)
        if self.dist == "loguniform":
            return np.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        if self._truncated():
            from scipy.stats import truncnorm  # scipy.stats takes about 0.5 s to import

            lo, hi = self._bounds()
            return truncnorm.ppf(u, lo, hi, loc=self.mean, scale=self.std)
        from scipy.special import ndtri  # as above: only a normal distribution needs scipy

        return self.mean + self.std * ndtri(u)

    def to_dict(self) -> dict[str, Any]:
        """The table of the spec file (parameters that are set)."""
        return {k: v for k, v in vars(self).items() if v is not None}


@dataclass(frozen=True)
class RandomSpec:
    """Random samples of several parameters, reproducible from ``seed``.

    Attributes
    ----------
    samples : int
        Number of samples N, >= 1.
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    parameters : dict of str to Distribution
        Dotted scene path -> distribution; parameter j takes column j of the unit-cube samples.
    method : {"random", "lhs"}
        Independent uniform draws, or a Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`).
    """

    samples: int
    seed: int
    parameters: dict[str, Distribution]
    method: str = "random"

    def __post_init__(self) -> None:
        for name in ("samples", "seed"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise SweepError(f"`random.{name}` must be an integer, got {value!r}")
        if not 1 <= self.samples <= MAX_CASES:
            raise SweepError(f"`random.samples` must be in [1, {MAX_CASES}], got {self.samples!r}")
        if self.seed < 0:
            raise SweepError(f"`random.seed` must be >= 0, got {self.seed!r}")
        if self.method not in SAMPLING_METHODS:
            raise SweepError(f"`random.method` must be one of {list(SAMPLING_METHODS)}, got {self.method!r}")
        if not self.parameters:
            raise SweepError("`random.parameters` is empty: give at least one parameter")

    def points(self) -> list[dict[str, float]]:
        """The N samples, each a dictionary path -> value (in the parameter's unit)."""
        rng = np.random.default_rng(self.seed)
        d = len(self.parameters)
        if self.method == "lhs":
            from scipy.stats import qmc  # scipy.stats takes about 0.5 s to import

            u = qmc.LatinHypercube(d, rng=rng).random(self.samples)
        else:
            u = rng.random((self.samples, d))
        columns = [dist.ppf(u[:, j]) for j, dist in enumerate(self.parameters.values())]
        return [{path: float(col[i]) for path, col in zip(self.parameters, columns, strict=True)}
                for i in range(self.samples)]

    def to_dict(self) -> dict[str, Any]:
        """The ``[random]`` table of the spec file."""
        return {"samples": int(self.samples), "seed": int(self.seed), "method": self.method,
                "parameters": {k: v.to_dict() for k, v in self.parameters.items()}}
