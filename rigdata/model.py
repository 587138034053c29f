"""The joint model driven by the measurement (the paper's section 4.2).

The paper drove its model with the measured input angle, velocity and acceleration. Here every
engine gets one scene: the joint at the rig's shaft angle and friction, the input angle history
from the conditioned measurement (phase-corrected, so the model's yoke sits where the speed
ratio says the real one was), and the measured output torque as the load, from the start of the
measured whole-revolution window; the scene's span is that window's revolutions, so the
computed mean efficiency covers exactly the revolutions the measured one does.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline

from cardan_exudyn import engines
from reference.results.result import Result
from reference.scene.drives import AngleDrive
from reference.scene.load import Load
from reference.scene.scene import Scene
from rigdata.conditioning import Conditioned

__all__ = ["MARGIN_REVOLUTIONS", "measured_scene", "computed_efficiency", "model_sensitivities"]

#: The margin of drive history kept after the window (so the engines find the window's end) [rev].
MARGIN_REVOLUTIONS = 0.05


def measured_scene(c: Conditioned, base: Scene, points_per_revolution: int = 120,
                   phase_shift: float = 0.0, load_offset: float = 0.0) -> Scene:
    """``base`` (joint, friction, numerics) driven and loaded by the conditioned measurement.

    Parameters
    ----------
    c : Conditioned
    base : Scene
        Supplies the joint, gravity, friction settings and numerics.
    points_per_revolution : int
        Knots of the drive and load histories per input revolution; the signals are low-passed
        at ``c.cutoff`` (10 harmonics by default), so 120 knots per revolution resolve them
        (12 per period of the highest harmonic kept).
    phase_shift : float
        Added to the estimated yoke phase [rad] (pi gives the other solution of the fit).
    load_offset : float
        Added to the measured load [N m] (for the model's sensitivity to the output transducer).

    Returns
    -------
    Scene
        Named ``<base>-measured``, its span the window's whole revolutions.
    """
    t_a, t_b = c.window
    period = (t_b - t_a) / c.revolutions
    end = min(t_b + MARGIN_REVOLUTIONS * period, float(c.t[-1]))
    n = max(8, int(math.ceil((end - t_a) / period * points_per_revolution)))
    times = np.linspace(t_a, end, n + 1)
    angle = CubicSpline(c.t, c.angle_in)(times) + c.phase + phase_shift
    torque = np.interp(times, c.t, c.torque_out) + load_offset
    return replace(base, drive=AngleDrive(tuple(times), tuple(angle)), load=Load(tuple(torque), tuple(times)),
                   revolutions=float(c.revolutions), record=replace(base.record, skip_revolutions=0.0),
                   name=f"{base.name}-measured", description=f"{base.name} driven by a measurement")


def computed_efficiency(result: Result) -> dict[str, Any]:
    """Mean and instantaneous computed efficiency from an engine result.

    ``mean_efficiency`` is 1 - lost work / input work over the window; the instantaneous one is
    the paper's: 1 - P_loss / P_in (its code "estimates the output power computing the power
    loss at the kinematic pairs", footnote 2), next to P_out / P_in.

    Parameters
    ----------
    result : Result
        From :func:`cardan_exudyn.engines.run`.

    Returns
    -------
    dict
        ``status`` (:class:`~reference.results.summary.Status`), ``reason``, ``engine``,
        ``mean_efficiency`` [-], ``work_ratio`` [-], ``mean_torque_in`` [N m] (None unless the
        status is ok), ``wall_time_s`` [s], ``efficiency_error_estimate`` [-] (the engine's own
        estimate of its mean-efficiency error, :class:`~reference.results.summary.Summary`); and when the
        run is ok and recorded its time series, ``series``: ``t`` [s], ``theta_in`` [rad],
        ``efficiency`` and ``power_ratio`` [-], ``torque_in`` [N m].
    """
    s = result.summary
    out = {"status": s.status, "reason": s.reason, "engine": s.engine,
           "mean_efficiency": s.mean_efficiency, "work_ratio": s.work_ratio,
           "mean_torque_in": s.mean_torque_in, "wall_time_s": s.wall_time_s,
           "efficiency_error_estimate": s.efficiency_error_estimate}
    if result.table is not None and result.success:
        out["series"] = _series(result.table)
    return out


def _series(table: Any) -> dict[str, np.ndarray]:
    """The curves of Figure 10 from a time table (see :func:`computed_efficiency`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        p_in = table["power_in"].to_numpy()
        return {"t": table["t"].to_numpy(), "theta_in": table["theta_in"].to_numpy(),
                "efficiency": 1.0 - table["power_loss"].to_numpy() / p_in,
                "power_ratio": table["power_out"].to_numpy() / p_in,
                "torque_in": table["torque_in"].to_numpy()}


def model_sensitivities(c: Conditioned, base: Scene, delta: float, baseline: float | None = None,
                        points_per_revolution: int = 120) -> dict[str, float]:
    """What the computed efficiency owes to the measurement (reference engine).

    Parameters
    ----------
    c : Conditioned
    base : Scene
    delta : float
        Load offset to difference over [N m].
    baseline : float, optional
        The reference engine's mean efficiency on the measured scene [-], when already run (else
        it is run here).
    points_per_revolution : int
        See :func:`measured_scene`.

    Returns
    -------
    dict
        ``load`` [1/(N m)]: the change per N m of load offset (the output transducer's error
        drives the model too, so it is correlated with the measured efficiency's);
        ``load_delta`` [N m]; ``phase_ambiguity`` [-]: the computed efficiency with the yoke half
        a turn away minus at the estimate (the fit cannot tell them apart).
    """
    def eta(**changes: float) -> float:
        result = engines.run(measured_scene(c, base, points_per_revolution, **changes), "reference")
        return float(result.mean_efficiency) if result.success else float("nan")

    baseline = eta() if baseline is None else baseline
    return {"load": (eta(load_offset=delta) - baseline) / delta, "load_delta": delta,
            "phase_ambiguity": eta(phase_shift=math.pi) - baseline}
