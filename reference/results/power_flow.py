"""Which way power flows through the joint over the averaging window, and the efficiency of that way.

``W_in`` is the drive's work on the input, ``W_out`` the output's on the load, ``W_loss >= 0``;
``W_in = W_out + W_loss + dE`` over the window. Directions, from the works' signs:

``input_to_output`` (``W_in > 0``, ``W_out > 0``)
    ``1 - W_loss / W_in`` (the paper's).
``output_to_input`` (``W_in < 0``, ``W_out < 0``)
    ``1 - W_loss / (-W_out)``.
``none`` (``W_in >= 0 >= W_out``)
    Efficiency 0, or None when no work is lost either.

Anything else, or an efficiency outside [0, 1], is ``unphysical`` (:func:`likely_cause`). A work
within :data:`WORK_FLOOR` of the window's energy scale counts as zero.
"""

from __future__ import annotations

from enum import Enum
from typing import NamedTuple

import numpy as np

__all__ = ["PowerFlow", "WORK_FLOOR", "FlowVerdict", "classify_works", "source_power", "sign_changes",
           "likely_cause"]

WORK_FLOOR = 1e-9
"""A window work below this fraction of the window's energy scale (the gross work
``int(|P_in| + |P_out| + |P_loss|) dt`` plus the largest mechanical energy) is rounding (the
reference engine's quadrature is accepted at 1e-9 of its scale) and counts as 0."""


class PowerFlow(str, Enum):
    """Direction of the net work through the joint over the window (a ``str`` enum)."""

    INPUT_TO_OUTPUT = "input_to_output"
    OUTPUT_TO_INPUT = "output_to_input"
    NONE = "none"

    def __str__(self) -> str:
        return self.value


class FlowVerdict(NamedTuple):
    """What a window's works say: ``power_flow`` (None when impossible), ``mean_efficiency`` and
    ``work_ratio`` [-] (None when undefined or impossible), a warning ``note``, the ``problem`` when
    unphysical, and ``excess_work`` [J], by how much.
    """

    power_flow: PowerFlow | None
    mean_efficiency: float | None
    work_ratio: float | None
    note: str = ""
    problem: str = ""
    excess_work: float = 0.0


def _works(w_in: float, w_out: float, w_loss: float) -> str:
    return f"input work {w_in:.6g} J, output work {w_out:.6g} J, lost {w_loss:.6g} J"


def classify_works(input_work: float, output_work: float, loss_work: float,
                   energy_scale: float = 0.0) -> FlowVerdict:
    """:class:`FlowVerdict` of the window's ``input_work``, ``output_work``, ``loss_work`` [J] (eq. (18)
    integrated, for the direction the work flows); works below ``WORK_FLOOR * energy_scale`` [J] count
    as zero.
    """
    w_in = float(input_work)
    w_out = float(output_work)
    w_loss = float(loss_work)
    works = _works(w_in, w_out, w_loss)
    if not all(np.isfinite((w_in, w_out, w_loss))):
        return FlowVerdict(None, None, None, problem=f"non-finite works ({works})")
    floor = WORK_FLOOR * abs(float(energy_scale))
    if w_loss < -floor:
        return FlowVerdict(None, None, None, problem=f"friction generates work ({works})",
                           excess_work=-w_loss)
    verdict = _by_direction(w_in, w_out, w_loss, floor, works)
    return _in_range(verdict, w_in, w_out, works)


def _by_direction(w_in: float, w_out: float, w_loss: float, floor: float, works: str) -> FlowVerdict:
    """The verdict the works' signs give (a work within ``floor`` [J] of zero counts as zero)."""
    if w_in > floor and w_out > floor:
        return FlowVerdict(PowerFlow.INPUT_TO_OUTPUT, 1.0 - w_loss / w_in, w_out / w_in)
    if w_in < -floor and w_out < -floor:
        return FlowVerdict(PowerFlow.OUTPUT_TO_INPUT, 1.0 - w_loss / -w_out, w_in / w_out,
                           note=f"power flows from the output to the input ({works}): the "
                                "efficiency is that of this direction, 1 - W_loss / (-W_out)")
    if w_in >= -floor and w_out <= floor and w_loss > floor:
        return FlowVerdict(PowerFlow.NONE, 0.0, 0.0,
                           note=f"neither shaft takes net work ({works}): nothing is "
                                "transmitted, the efficiency is 0")
    if w_in >= -floor and w_out <= floor:
        return FlowVerdict(PowerFlow.NONE, None, None,
                           note=f"no work is transmitted or lost ({works}): the efficiency is "
                                "undefined")
    return FlowVerdict(None, None, None,
                       problem=f"the shafts take out work that nobody supplies ({works})",
                       excess_work=max(-w_in, 0.0) + max(w_out, 0.0))


def _in_range(verdict: FlowVerdict, w_in: float, w_out: float, works: str) -> FlowVerdict:
    """``verdict``, or a problem when its mean efficiency is outside [0, 1]."""
    eta = verdict.mean_efficiency
    if eta is None or 0.0 <= eta <= 1.0:
        return verdict
    source = w_in if verdict.power_flow == PowerFlow.INPUT_TO_OUTPUT else -w_out
    return verdict._replace(mean_efficiency=None, work_ratio=None, problem=(
        f"mean efficiency {eta:.6g} is outside [0, 1] ({verdict.power_flow}: {works})"),
        excess_work=max(-eta, eta - 1.0) * source)


def source_power(flow: PowerFlow | str | None, power_in: np.ndarray, power_out: np.ndarray) -> np.ndarray:
    """Power [W] the source shaft feeds in: ``power_in``, or ``-power_out`` when ``flow`` is output to input.
    """
    if flow == PowerFlow.OUTPUT_TO_INPUT:
        return -np.asarray(power_out, float)
    return np.asarray(power_in, float)


def sign_changes(values: np.ndarray) -> int:
    """How often ``values`` change sign (exact zeros skipped)."""
    signs = np.sign(np.asarray(values, float))
    signs = signs[signs != 0.0]
    return int(np.count_nonzero(signs[1:] != signs[:-1]))


def likely_cause(excess_work: float, energy_change: float, residual: float) -> str:
    """Why a window's works are unphysical, from the ``excess_work``, the mechanical ``energy_change`` and
    the balance ``residual`` ``W_in - W_out - W_loss - dE`` [J].
    """
    if abs(residual) >= 0.5 * excess_work:
        return (f"the works do not balance the change of mechanical energy (residual {residual:.3g} J "
                f"against {excess_work:.3g} J out of range): the integration is not accurate enough "
                "for this scene (too coarse a step, or friction lagged through a self-lock); refine "
                "numerics.dt or numerics.accuracy")
    if abs(energy_change) >= 0.5 * excess_work:
        return (f"the mechanical energy changes by {energy_change:.3g} J over the window: the "
                "motion is not periodic (a drive or load that speeds the joint up or slows it down, "
                "gravity against the drive); average over more revolutions or skip the start-up")
    return "the work transmitted is at the level of the energy balance's rounding"
