"""The columns of the time table every engine returns (SI units).

``t`` [s]; ``theta_in``, ``theta_out`` [rad] (unwrapped, output measured about its own axis from
its yoke position at input angle 0); ``omega_in``, ``omega_out`` [rad/s];
``torque_in`` [N m], torque the drive applies to the input shaft about its axis;
``torque_out`` [N m], torque the output shaft applies to the load about the output axis
(the resisting torque); ``power_in = torque_in * omega_in``, ``power_out = torque_out * omega_out``
[W]; ``power_loss_<pair>`` [W] and their sum ``power_loss``; ``efficiency`` [-], the
instantaneous efficiency of eq. (18), ``1 - power_loss / power_in`` (NaN where power_in is 0);
``energy_kinetic``, ``energy_potential`` [J], mechanical energy of the three bodies (potential
energy zero at the joint centre).

Per pair, ``<pair>_fx, _fy, _fz`` [N] and ``<pair>_mx, _my, _mz`` [N m]: the force and moment that
body ``a`` of the pair exerts on body ``b`` (see :data:`reference.scene.joint.PAIR_BODIES`), about the
pair's origin (on the axis, moving with body ``b`` when a pair with mounting errors slides), in
the pair frame (z along the pair axis) attached to body ``a``. The constraint
part excludes the applied friction; friction appears in ``<pair>_friction_torque`` [N m] and
``<pair>_friction_force`` [N] (on body b, about / along the pair axis), with the relative motion
``<pair>_omega_rel`` [rad/s] and ``<pair>_slide_rel`` [m/s] of b with respect to a.
"""

from __future__ import annotations

import numpy as np

from reference.scene.joint import PAIR_NAMES

__all__ = ["KINEMATIC_COLUMNS", "POWER_COLUMNS", "REACTION_SUFFIXES", "PAIR_SUFFIXES", "pair_columns",
           "table_columns", "instantaneous_efficiency"]

KINEMATIC_COLUMNS = ("t", "theta_in", "theta_out", "omega_in", "omega_out")
POWER_COLUMNS = ("torque_in", "torque_out", "power_in", "power_out", "power_loss", "efficiency",
                 "energy_kinetic", "energy_potential")
REACTION_SUFFIXES = ("fx", "fy", "fz", "mx", "my", "mz")
PAIR_SUFFIXES = REACTION_SUFFIXES + ("friction_torque", "friction_force", "omega_rel", "slide_rel")


def pair_columns(pair: str) -> list[str]:
    """The columns of ``pair`` (one of :data:`reference.scene.joint.PAIR_NAMES`), in order."""
    return [f"{pair}_{s}" for s in PAIR_SUFFIXES]


def table_columns() -> list[str]:
    """All columns of the time table, in order."""
    cols = list(KINEMATIC_COLUMNS) + list(POWER_COLUMNS)
    cols += [f"power_loss_{p}" for p in PAIR_NAMES]
    for p in PAIR_NAMES:
        cols += pair_columns(p)
    return cols


def instantaneous_efficiency(power_in: np.ndarray, power_loss: np.ndarray) -> np.ndarray:
    """Eq. (18), ``1 - P_loss / P_in`` [-] from ``power_in``, ``power_loss`` [W]; NaN where ``P_in`` is
    exactly zero.
    """
    p_in = np.asarray(power_in, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(p_in != 0.0, 1.0 - np.asarray(power_loss, float) / p_in, np.nan)
