"""The joint model driven by the measurement (paper, section 4.2): the rig joint with the phase-corrected
measured input angle as drive and the measured output torque as load, over the measured
whole-revolution window, so computed and measured mean efficiency cover the same revolutions.
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
    """``base`` (joint, friction, numerics) driven and loaded by ``c``, named ``<base>-measured``.

    ``points_per_revolution`` knots per input revolution (12 per period of the 10th harmonic);
    ``phase_shift`` [rad] added to the yoke phase (pi: the other fit); ``load_offset`` [N m] added to the
    load.
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

    Mean: 1 - lost work / input work; instantaneous: the paper's 1 - P_loss / P_in (footnote 2) and
    P_out / P_in. Keys: ``status``, ``reason``, ``engine``, ``mean_efficiency``, ``work_ratio``,
    ``mean_torque_in`` (None unless ok), ``wall_time_s``, ``efficiency_error_estimate``; ``series``
    (``t``, ``theta_in``, ``efficiency``, ``power_ratio``, ``torque_in``) when ok and recorded.
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
    """What the computed efficiency owes to the measurement (reference engine, ``baseline`` if already run).

    ``load`` [1/(N m)]: change per N m of load offset (differenced over ``delta``); ``load_delta`` [N m];
    ``phase_ambiguity`` [-]: efficiency with the yoke half a turn away minus at the estimate.
    """
    def eta(**changes: float) -> float:
        result = engines.run(measured_scene(c, base, points_per_revolution, **changes), "reference")
        return float(result.mean_efficiency) if result.success else float("nan")

    baseline = eta() if baseline is None else baseline
    return {"load": (eta(load_offset=delta) - baseline) / delta, "load_delta": delta,
            "phase_ambiguity": eta(phase_shift=math.pi) - baseline}
