"""How a time-stepping engine's friction coupling behaved over a run: :class:`FrictionDiagnostics`,
the summary's ``friction`` table (``docs/outputs.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

__all__ = ["FrictionDiagnostics"]


@dataclass(frozen=True)
class FrictionDiagnostics:
    """The friction coupling's counters and loop-gain estimates of one run; None where not measured.

    Attributes
    ----------
    coupling : str
        The scene's ``friction.coupling``.
    sign_bands_m_s : mapping of str to (float, float, float)
        Per pair with friction, its ramp half-widths [m/s]: rotation, sliding, resultant.
    pairs_with_friction : tuple of str
    tolerance : float or None
        Relative tolerance of the per-step fixed point [-] (None: lagged).
    mean_iterations_per_step, max_iterations_in_a_step : float, int
        Friction evaluations per accepted step.
    unconverged_steps : int
        Steps that reached the iteration limit but still contracted.
    escalated_to_converged_at : float or None
        Time [s] the extrapolated coupling switched to the converged one.
    steps_iterated_at_reversals : int
        Extrapolated coupling: steps solved to their fixed point at a motion reversal.
    loop_gain_estimate, loop_gain_estimate_max : float or None
        Median and largest loop-gain estimate [-] (>= 1: no consistent friction).
    gain_probes : int
        Extrapolated coupling: steps solved twice to probe the loop gain.
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
        """Inverse of :meth:`to_dict`; None for a table with unknown keys or without ``coupling``."""
        if "coupling" not in data or not set(data) <= {f.name for f in fields(cls)}:
            return None
        values = dict(data)
        values["sign_bands_m_s"] = {p: tuple(b) for p, b in (data.get("sign_bands_m_s") or {}).items()}
        values["pairs_with_friction"] = tuple(data.get("pairs_with_friction") or ())
        return cls(**values)
