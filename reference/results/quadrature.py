"""Integrals over a time table that know where friction jumps.

A time-stepping engine samples the powers at its steps; the mean efficiency is their integral
over whole revolutions. Where a pair's relative motion reverses, its friction changes sign
within a sign ramp far narrower than a step (:mod:`reference.physics.bands`), and the drive torque and
every pair's reaction jump with it. The trapezoid between the two rows around such a jump
integrates a straight line across the step, an error of half the jump times the step at every
reversal: first order in the step, whatever the engine's own order.

:func:`jump_breaks` finds every reversal from the table's relative speeds (the crossing instant
interpolated linearly between the rows around it) and :func:`segment_integrals` integrates each
side of it along the line through the two nearest rows on that side. A row closer than :data:`NEAR` of a
step to the crossing (in particular a row exactly at it, as on a constant-speed grid of 4k steps
per revolution, where the crossings of a symmetric joint fall on rows) may lie inside the sign
ramp, where its value belongs to neither side: it is left out and the two steps around it are
integrated as one; so are the rows of a ramp the steps partly resolve (:data:`RAMP_GROWTH`).
Measured on the reference engine's exact rows: docs/accuracy.md#step-model-constants
(``tests/test_reference_quadrature.py`` pins the gain over the plain trapezoid).
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
    """``(a, b, t*)``: consecutive clear rows ``a < b`` with opposite signs of the speed ``w``,
    and the crossing instant ``t*`` interpolated linearly between them. A row is clear when its
    speed is above ``noise`` and its friction ``f`` above :data:`RAMP_SHARE` of the pair's
    largest: rows in between (in the sign ramp, or exactly at the crossing) are skipped."""
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
    """The first row from ``row`` in the direction ``away`` that is off the sign ramp (its
    friction within :data:`RAMP_GROWTH` of the next row's, going away from the crossing; at
    most :data:`RESOLVED_ROWS` + 1 rows away)."""
    for _ in range(RESOLVED_ROWS + 1):
        beyond = row + away
        if not 0 <= beyond < f.size or abs(f[beyond]) <= (1.0 + RAMP_GROWTH) * abs(f[row]):
            break
        row = beyond
    return row


def jump_breaks(columns: Mapping[str, np.ndarray]) -> list[tuple[int, int, float]]:
    """Where the integrand jumps: ``(a, b, t*)`` for every reversal of a pair with friction.

    Rows ``a`` and ``b`` are the nearest on either side whose values are used (a row within
    :data:`NEAR` of a step of the crossing is skipped); ``t*`` is the crossing [s]. Pairs whose
    friction column is zero throughout (or absent) give none, and so do speeds that only
    scatter around zero (below :data:`NOISE` of the input speed, per metre for sliding: a pair
    that does not move, e.g. the spider pairs of a straight joint); two reversals that would
    share a step keep the first (the trapezoid takes the other).
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
    """Integral of ``y dt`` over each step: the trapezoid, except across the friction jumps.

    Across a break each side of the crossing follows the straight line through the row on its
    side and the next one beyond it (a constant at the table's ends). A jump is then integrated
    exactly to second order, and so is a sign ramp that the steps resolve (where the trapezoid
    is right too): either way the error stays O(h^2).

    Parameters
    ----------
    y : ndarray, shape (n,)
        The integrand (e.g. a power [W]).
    t : ndarray, shape (n,)
        Time [s].
    breaks : sequence of (int, int, float)
        :func:`jump_breaks`: rows ``a < b`` and the crossing instant [s].

    Returns
    -------
    ndarray, shape (n - 1,)
        Per step the integral (e.g. a work [J]).
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
