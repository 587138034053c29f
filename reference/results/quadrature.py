"""Integrals over a time table that know where friction jumps.

Why: where a pair reverses, friction (and the reactions and drive torque) jumps within a ramp far
narrower than a step, and the trapezoid across it errs by half the jump times the step, first
order. :func:`jump_breaks` finds each reversal; :func:`segment_integrals` integrates each side
along the line through its two nearest rows, leaving out rows within :data:`NEAR` of the crossing
or on a partly resolved ramp (:data:`RAMP_GROWTH`). Measured: docs/accuracy.md#step-model-constants.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from reference.scene.joint import PAIR_NAMES

__all__ = ["NEAR", "NOISE", "RAMP_SHARE", "RAMP_GROWTH", "RESOLVED_ROWS", "jump_breaks", "segment_integrals"]

NEAR = 0.25
"""A row within this fraction of a step of a crossing may be inside the sign ramp: left out."""
NOISE = 1e-6
"""Relative speeds below this share of the input speed [rad/s] (or [m/s] per metre) are taken as
zero: the constraint solver's residue, not motion (a crossing within it is within NEAR anyway)."""
RAMP_SHARE = 1e-3
"""A row whose friction is below this share of the pair's largest is inside its sign ramp (or
at rest): its sign is not a side of a jump."""
RAMP_GROWTH = 0.1
"""Going away from a crossing, a row whose friction is more than this share below the next
row's is still on the sign ramp: it is left out too (the ramp's signed part, symmetric about the
crossing, integrates as the jump at its middle). Away from ramps friction changes far less per
step."""
RESOLVED_ROWS = 4
"""A ramp with more rows than this on it is resolved by the steps: the trapezoid is accurate across
it (second order), and no break is made. (A ramp the steps only partly resolve is integrated as
the jump at its middle, which leaves out its dip in the powers, where the friction's magnitude
passes through zero: an error proportional to the ramp's width, small for the default bands.)"""


_MOTIONS = (("friction_torque", "omega_rel"), ("friction_force", "slide_rel"))


def _crossings(w: np.ndarray, f: np.ndarray, t: np.ndarray, noise: float) -> list[tuple[int, int, float]]:
    """``(a, b, t*)``: consecutive clear rows with opposite signs of speed ``w`` and the crossing instant
    between them; a row is clear when ``|w|`` > ``noise`` and ``f`` above :data:`RAMP_SHARE` of its max.
    """
    clear = (np.abs(w) > noise) & (np.abs(f) >= RAMP_SHARE * np.max(np.abs(f)))
    rows = np.flatnonzero(clear)
    if rows.size < 2:
        return []
    a, b = rows[:-1], rows[1:]
    change = np.sign(w[a]) != np.sign(w[b])
    a, b = a[change], b[change]
    ts = t[a] + (t[b] - t[a]) * w[a] / (w[a] - w[b])
    return list(zip(a.tolist(), b.tolist(), ts.tolist(), strict=True))


def _off_ramp(f: np.ndarray, row: int, away: int) -> int:
    """The first row from ``row`` in direction ``away`` off the sign ramp (friction ``f`` within
    :data:`RAMP_GROWTH` of the next row's; at most :data:`RESOLVED_ROWS` + 1 rows away).
    """
    for _ in range(RESOLVED_ROWS + 1):
        beyond = row + away
        if not 0 <= beyond < f.size or abs(f[beyond]) <= (1.0 + RAMP_GROWTH) * abs(f[row]):
            break
        row = beyond
    return row


def jump_breaks(columns: Mapping[str, np.ndarray]) -> list[tuple[int, int, float]]:
    """``(a, b, t*)`` for every reversal of a pair with friction in ``columns``: the nearest used rows
    either side and the crossing [s]. Speeds below :data:`NOISE` of the input speed give none; of two
    reversals sharing a step the first is kept.
    """
    t = np.asarray(columns["t"], float)
    last = t.size - 1
    noise = NOISE * float(np.max(np.abs(np.asarray(columns["omega_in"], float))))
    used = np.zeros(t.size, bool)
    out = []
    for p in PAIR_NAMES:
        for load, motion in _MOTIONS:
            f = columns.get(f"{p}_{load}")
            w = columns.get(f"{p}_{motion}")
            if f is None or w is None or not np.any(np.asarray(f, float)):
                continue
            f = np.asarray(f, float)
            for a, b, ts in _crossings(np.asarray(w, float), f, t, noise):
                a = _off_ramp(f, a, -1)
                b = _off_ramp(f, b, +1)
                if b - a - 1 > RESOLVED_ROWS:
                    continue
                if b == a + 1:
                    frac = (ts - t[a]) / (t[b] - t[a])
                    if frac < NEAR and a >= 1:
                        a -= 1
                    elif frac > 1.0 - NEAR and b < last:
                        b += 1
                if not used[a:b + 1].any():
                    used[a:b + 1] = True
                    out.append((a, b, ts))
    return out


def segment_integrals(y: np.ndarray, t: np.ndarray,
                      breaks: Sequence[tuple[int, int, float]] = ()) -> np.ndarray:
    """Per step (n - 1,) the integral of ``y dt`` over time ``t`` [s]: the trapezoid, except across the
    ``breaks`` (:func:`jump_breaks`), where each side follows the line through its row and the next
    beyond it (O(h^2) either way).
    """
    y = np.asarray(y, float)
    t = np.asarray(t, float)
    seg = 0.5 * np.diff(t) * (y[:-1] + y[1:])
    last = t.size - 1
    for a, b, ts in breaks:
        left = _line(y, t, a, a - 1) if a >= 1 else (y[a], 0.0)
        right = _line(y, t, b, b + 1) if b < last else (y[b], 0.0)
        for k in range(a, b):
            lo, hi = t[k], t[k + 1]
            mid = min(hi, max(lo, ts))
            seg[k] = ((mid - lo) * _at(left, t[a], 0.5 * (lo + mid))
                      + (hi - mid) * _at(right, t[b], 0.5 * (mid + hi)))
    return seg


def _line(y: np.ndarray, t: np.ndarray, row: int, other: int) -> tuple[float, float]:
    """Value at ``row`` and slope of the line through rows ``row`` and ``other``."""
    return float(y[row]), float((y[row] - y[other]) / (t[row] - t[other]))


def _at(line: tuple[float, float], t_row: float, t: float) -> float:
    return line[0] + line[1] * (t - t_row)
