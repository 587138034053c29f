"""The reference engine's resolution: table rows, quadrature panels and nodes, ODE tolerances."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.results.summary import OptionsError

__all__ = ["ReferenceOptions"]


@dataclass(frozen=True)
class ReferenceOptions:
    """Resolution of the reference engine.

    Attributes
    ----------
    samples_per_revolution : int or None
        Table rows per input revolution; None: the scene's ``numerics.dt`` when set, else 360.
    panels_per_revolution : int
        Initial Gauss-Legendre panels per revolution for the work integrals (refined adaptively).
    gauss_nodes : int
        Nodes per panel.
    quadrature_rtol : float
        A panel is accepted when its halves and the whole agree to this fraction of the input work,
        scaled by its share of the window.
    ode_rtol, ode_atol : float
        ``solve_ivp`` tolerances of torque-driven scenes (atol on the angle [rad] and, by
        :func:`reference.engine.torque_ode.speed_tolerance`, the speed).
    """

    samples_per_revolution: int | None = None
    panels_per_revolution: int = 8
    gauss_nodes: int = 8
    quadrature_rtol: float = 1e-9
    ode_rtol: float = 1e-11
    ode_atol: float = 1e-11

    def __post_init__(self) -> None:
        spr = self.samples_per_revolution
        if spr is not None and (isinstance(spr, bool) or not isinstance(spr, (int, np.integer))
                                or spr < 1):
            raise OptionsError(f"`samples_per_revolution` must be a positive integer, got {spr!r}")
        for name in ("panels_per_revolution", "gauss_nodes"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise OptionsError(f"`{name}` must be a positive integer, got {v!r}")
        for name in ("ode_rtol", "ode_atol", "quadrature_rtol"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and 0.0 < v < 1.0):
                raise OptionsError(f"`{name}` must be in (0, 1), got {v!r}")
