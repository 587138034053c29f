"""How a time-stepping engine's friction coupling behaved over a run: :class:`FrictionDiagnostics`.

On disk it is the summary's ``friction`` table (``docs/outputs.md``); the coupling schemes are
described in :mod:`cardan_exudyn.model.coupling` and its schemes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

__all__ = ["FrictionDiagnostics"]


@dataclass(frozen=True)
class FrictionDiagnostics:
    """The friction coupling's counters and loop-gain estimates of one run.

    A field is None where the coupling does not measure it, or where a summary read from disk
    did not have it.

    Attributes
    ----------
    coupling : str
        The scene's ``friction.coupling`` (``extrapolated``, ``converged``, ``lagged``).
    sign_bands_m_s : mapping of str to (float, float, float)
        Per pair with friction, the half-widths of its sign ramps [m/s]: rotation (surface
        speed), sliding, resultant.
    pairs_with_friction : tuple of str
        The pairs with a non-zero friction coefficient, in order.
    tolerance : float or None
        Relative tolerance of the per-step fixed point [-]; None for the lagged coupling.
    mean_iterations_per_step, max_iterations_in_a_step : float, int
        Friction evaluations (Newton solves) per accepted step: mean and largest [-].
    unconverged_steps : int
        Steps whose fixed-point iteration reached its limit but still contracted.
    escalated_to_converged_at : float or None
        Time [s] at which the extrapolated coupling switched to the converged one (a probed loop
        gain above its limit, or growth of the friction); None when it never did.
    steps_iterated_at_reversals : int
        Extrapolated coupling: steps solved to their fixed point because a motion reversed.
    loop_gain_estimate, loop_gain_estimate_max : float or None
        Median and largest estimate of the friction feedback's loop gain [-] (friction ->
        reactions -> friction; >= 1: no consistent friction); None when nothing was measured.
    gain_probes : int
        Extrapolated coupling: steps solved twice to probe the loop gain (a probe whose friction
        did not move beyond rounding gives no estimate).
    """

    coupling: str
    sign_bands_m_s: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    pairs_with_friction: tuple[str, ...] = ()
    tolerance: float | None = None
    mean_iterations_per_step: float | None = None
    max_iterations_in_a_step: int | None = None
    unconverged_steps: int | None = None
    escalated_to_converged_at: float | None = None
    steps_iterated_at_reversals: int | None = None
    loop_gain_estimate: float | None = None
    loop_gain_estimate_max: float | None = None
    gain_probes: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The summary's ``friction`` table: every field, the bands and pairs as lists."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["sign_bands_m_s"] = {p: list(b) for p, b in self.sign_bands_m_s.items()}
        out["pairs_with_friction"] = list(self.pairs_with_friction)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FrictionDiagnostics | None:
        """Inverse of :meth:`to_dict`; None for a table with keys this version does not know
        (or without ``coupling``)."""
        if "coupling" not in data or not set(data) <= {f.name for f in fields(cls)}:
            return None
        values = dict(data)
        values["sign_bands_m_s"] = {p: tuple(b) for p, b in (data.get("sign_bands_m_s") or {}).items()}
        values["pairs_with_friction"] = tuple(data.get("pairs_with_friction") or ())
        return cls(**values)
