"""The MuJoCo engine's solver settings (:class:`MujocoOptions`), validated on construction; importing
it needs no MuJoCo. Defaults and their study: ``docs/mujoco.md``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from reference.results.summary import OptionsError

__all__ = ["INTEGRATORS", "MUJOCO_DEFAULT_SOLREF", "MUJOCO_DEFAULT_SOLIMP", "STIFF_SOLIMP",
           "MujocoOptions"]

INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast", "discrete")
"""MuJoCo's ``option/integrator`` values."""
MUJOCO_DEFAULT_SOLREF = (0.02, 1.0)
"""MuJoCo's own ``solref`` (timeconst [s], dampratio [-]): the contact override's when not given."""
MUJOCO_DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
"""MuJoCo's own ``solimp`` (d0, dwidth, width, midpoint, power)."""
STIFF_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
"""Impedance at MuJoCo's cap ``mjMAXIMP = 0.9999`` (larger values are clamped to it)."""


def _floats(name: str, value: Any) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise OptionsError(f"`{name}` must be a sequence of numbers, got {value!r}") from None


def _solref(name: str, value: Any) -> tuple[float, ...]:
    """``value`` as a ``solref``: ``(timeconst > 0, dampratio > 0)`` or
    ``(-stiffness < 0, -damping <= 0)``."""
    ref = _floats(name, value)
    if len(ref) != 2 or not (min(ref) > 0.0 or (ref[0] < 0.0 and ref[1] <= 0.0)):
        raise OptionsError(f"`{name}` must be (timeconst > 0, dampratio > 0) or "
                           f"(-stiffness < 0, -damping <= 0), got {value!r}")
    return ref


def _solimp(name: str, value: Any) -> tuple[float, ...]:
    """``value`` as a ``solimp``: five numbers with ``0 < d0, dwidth < 1``."""
    imp = _floats(name, value)
    if len(imp) != 5 or not (0.0 < imp[0] < 1.0 and 0.0 < imp[1] < 1.0):
        raise OptionsError(f"`{name}` must be 5 numbers with 0 < d0, dwidth < 1, got {value!r}")
    return imp


@dataclass(frozen=True)
class MujocoOptions:
    """Solver settings of the MuJoCo engine; the defaults are the recommended ones.

    Attributes
    ----------
    integrator : str
        One of :data:`INTEGRATORS`.
    timestep : float or None
        Time step [s]; None: ``scene.numerics.dt``, else the step meeting ``numerics.accuracy``.
    timeconst_steps : float
        Constraint time constant in steps: ``solref = (timeconst_steps * dt, dampratio)`` [-].
    dampratio : float
        Damping ratio of the constraint stabilisation, when ``solref`` is None [-].
    solref : tuple of 2 float or None
        Explicit ``solref`` of every equality: ``(timeconst [s], dampratio)`` or
        ``(-stiffness [1/s^2], -damping [1/s])``.
    solimp : tuple of 5 float
        ``(d0, dwidth, width [m or rad], midpoint, power)`` of every equality.
    refsafe : bool
        MuJoCo's ``refsafe``: time constant at least ``2 dt``.
    iterations, tolerance : int, float
        Constraint-solver iterations and tolerance [-].
    noslip_iterations : int
        Noslip iterations (friction rows only; there are none).
    o_solref, o_solimp : tuple or None
        Either given: MuJoCo's contact override on, with these (contacts only; there are none).
    reference_inertia : float
        Inertia of the drive-reference body [kg m^2]: the drive torque changes its speed by
        ``torque * dt / reference_inertia`` within a step.
    """

    integrator: str = "RK4"
    timestep: float | None = None
    timeconst_steps: float = 20.0
    dampratio: float = 1.0
    solref: tuple | None = None
    solimp: tuple = STIFF_SOLIMP
    refsafe: bool = True
    iterations: int = 100
    tolerance: float = 1e-8
    noslip_iterations: int = 0
    o_solref: tuple | None = None
    o_solimp: tuple | None = None
    reference_inertia: float = 1e6

    def __post_init__(self) -> None:
        if self.integrator not in INTEGRATORS:
            raise OptionsError(f"`integrator` must be one of {list(INTEGRATORS)}, got {self.integrator!r}")
        for name in ("timeconst_steps", "dampratio", "reference_inertia"):
            if not getattr(self, name) > 0.0:
                raise OptionsError(f"`{name}` must be positive, got {getattr(self, name)!r}")
        if self.timestep is not None and not self.timestep > 0.0:
            raise OptionsError(f"`timestep` must be positive or None, got {self.timestep!r}")
        for name, check in (("solref", _solref), ("o_solref", _solref), ("o_solimp", _solimp)):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, check(name, getattr(self, name)))
        object.__setattr__(self, "solimp", _solimp("solimp", self.solimp))
        self._check_counts()
        if not self.tolerance >= 0.0:
            raise OptionsError(f"`tolerance` must be >= 0, got {self.tolerance!r}")

    def _check_counts(self) -> None:
        """``iterations`` >= 1 and ``noslip_iterations`` >= 0, both integers."""
        for name in ("iterations", "noslip_iterations"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < (name == "iterations"):
                raise OptionsError(f"`{name}` must be a non-negative integer (iterations >= 1), "
                                   f"got {value!r}")

    def solref_for(self, dt: float) -> tuple[float, float]:
        """The ``solref`` used at time step ``dt`` [s]: the explicit one, else
        ``(timeconst_steps * dt, dampratio)``."""
        return self.solref if self.solref is not None else (self.timeconst_steps * dt, self.dampratio)
