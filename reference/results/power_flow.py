"""Which way power flows through the joint over the averaging window, and the efficiency of that way.

The paper's efficiency (eq. (18), ``1 - P_loss / P_in``, and its mean ``1 - W_loss / W_in``) takes
the drive as the source and the load as the sink. A reversed joint is the same physics: run the
scene with speed and load reversed (angle history, torque drive) and the mirror image of the
joint in the plane of the shafts turns backwards with the same reactions, the same friction and
the same efficiency. An aiding load (one that turns the output the way it already goes) or a
drive that brakes makes the output shaft the source. So the efficiency is defined for the
direction the work actually flows, from the signs of the window's works.

Sign conventions (:mod:`reference.results.summary`): ``W_in`` is the work the drive does on the input
shaft, ``W_out`` the work the output shaft does on the load, ``W_loss`` the friction losses
(never negative); over the window ``W_in = W_out + W_loss + dE`` (``dE`` the change of mechanical
energy, zero over whole revolutions of a periodic motion).

``input_to_output`` (``W_in > 0``, ``W_out > 0``)
    The drive supplies, the load takes: ``1 - W_loss / W_in`` (the paper's).
``output_to_input`` (``W_in < 0``, ``W_out < 0``)
    The load drives the joint and the drive absorbs: the source supplies ``-W_out``, so
    ``1 - W_loss / (-W_out)``.
``none`` (``W_in >= 0 >= W_out``: neither shaft takes net work, e.g. no load)
    Nothing is transmitted: the efficiency is 0, or undefined (None) when no work is lost either
    (frictionless and unloaded: every work is zero).

Anything else (work leaves through a shaft and none enters) is impossible over a periodic
window, and so is an efficiency outside [0, 1]: the summary's status is then ``unphysical``
(:func:`likely_cause` says why it probably happened). A work within :data:`WORK_FLOOR` of the
window's energy scale counts as zero.
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
    """What the works of a window say.

    Attributes
    ----------
    power_flow : PowerFlow or None
        None when the works are impossible (``problem`` says why).
    mean_efficiency, work_ratio : float or None
        One minus lost over supplied work, and received over supplied work [-]; None when
        undefined or impossible.
    note : str
        A sentence for the summary's warnings (empty for the paper's direction).
    problem : str
        Why the works are unphysical (empty when they are not).
    excess_work : float
        By how much they are [J]: the efficiency's distance from [0, 1] times the source work,
        the work taken out that nobody supplied, or the work friction generated.
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
    """Direction of the power flow and its efficiency from the window's works [J].

    Parameters
    ----------
    input_work, output_work, loss_work : float
        ``W_in``, ``W_out``, ``W_loss`` over the window [J] (signs as in the module docstring).
    energy_scale : float
        ``int(|P_in| + |P_out| + |P_loss|) dt`` over the window plus the largest mechanical
        energy [J]: works below ``WORK_FLOOR * energy_scale`` count as zero (0: only exact zeros
        do).

    Returns
    -------
    FlowVerdict

    References
    ----------
    Eq. (18) of the paper, integrated over the window, for the direction the work flows.
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
    """Power the source shaft feeds into the joint.

    Parameters
    ----------
    flow : PowerFlow, str or None
        The window's power flow.
    power_in, power_out : ndarray, shape (n,)
        Input and output power [W].

    Returns
    -------
    ndarray, shape (n,)
        ``P_in``, or ``-P_out`` when the power flows from the output to the input [W].
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
    """Why a window's works are unphysical.

    Parameters
    ----------
    excess_work : float
        The work by which they are impossible [J]: how far the efficiency is outside [0, 1]
        times the source work, or the work the shafts take out that nobody supplied.
    energy_change : float
        ``dE``, change of mechanical energy over the window [J].
    residual : float
        The energy-balance residual ``W_in - W_out - W_loss - dE`` [J].
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
