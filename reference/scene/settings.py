"""A scene's engine-independent settings: accuracy, friction coupling and regularisation, records."""

from __future__ import annotations

from dataclasses import dataclass

from reference.scene.validation import MAX_STEPS, SceneError, non_negative, positive, set_field

__all__ = ["COUPLINGS", "DEFAULT_SIGN_BAND_RELATIVE", "FRICTION_LAWS", "MAX_ITERATIONS", "FrictionSettings",
           "Numerics", "Record"]

MAX_ITERATIONS = 10_000
"""Most friction updates per step ``FrictionSettings.max_iterations`` may ask for."""


@dataclass(frozen=True)
class Numerics:
    """Engine-independent accuracy settings.

    Attributes
    ----------
    dt : float or None
        Time step [s]; None: the engine chooses it from ``accuracy``.
    accuracy : float
        Target absolute error of the mean efficiency [-], also the target relative error of
        omega_out/omega_in (``docs/accuracy.md``).
    richardson : bool
        Time stepping at ``h`` and ``h / 2``, extrapolated (``docs/bench.md``); reference: ignored.
    """

    dt: float | None = None
    accuracy: float = 1e-3
    richardson: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.richardson, bool):
            raise SceneError(f"`richardson` must be true or false, got {self.richardson!r}")
        if self.dt is not None:
            set_field(self, "dt", positive("dt", self.dt))
        acc = positive("accuracy", self.accuracy)
        if acc >= 1.0:
            raise SceneError(f"`accuracy` must be < 1, got {acc!r}")
        set_field(self, "accuracy", acc)


COUPLINGS = ("converged", "lagged", "uncoupled", "extrapolated")
FRICTION_LAWS = ("paper", "resultant")
DEFAULT_SIGN_BAND_RELATIVE = 1e-3
"""Default ``FrictionSettings.sign_band_relative`` [-] (``docs/paper.md``, "Friction at every speed")."""


@dataclass(frozen=True)
class FrictionSettings:
    """How the friction of eqs. (1)-(5) is coupled to the reactions and regularised.

    Attributes
    ----------
    coupling : str
        ``"extrapolated"`` (default): one Newton solve per step, the law on extrapolated inputs;
        ``"converged"``: friction and reactions iterated to a fixed point within each step;
        ``"lagged"``: the paper's scheme (section 3.1), a step's end reactions set the next step's
        friction; ``"uncoupled"``: eqs. (3), (5) evaluated on the frictionless reactions, not applied
        (a first-order estimate). The reference solves the fixed point for all but the last.
    sign_band : float or None
        One absolute ramp width [m/s] for every pair, ``clip(v / sign_band, -1, 1)`` of the relative
        surface or sliding speed; 0: exact sign; None (default): the relative band.
    sign_band_relative : float or None
        Ramp width as a fraction of each pair's characteristic speed [-]
        (:func:`reference.physics.bands.sign_bands`); 0: exact sign; None:
        :data:`DEFAULT_SIGN_BAND_RELATIVE` unless ``sign_band`` is given. At most one of the two.
    tolerance : float
        Converged coupling: accepted when the largest change of a friction load is below this times
        the largest one (forces as torque at the journal radius, ``F d / 2``).
    max_iterations : int
        Converged coupling: friction updates per step before it is declared not converged.
    law : str
        ``"paper"`` (default): eqs. (3), (5) as written, torque and axial force each with the full
        Coulomb load; ``"resultant"``: one Coulomb force ``f N`` opposing the contact's resultant slip
        (``docs/scenes.md``, "Friction law"). They agree for a pair that does not slide.
    """

    coupling: str = "extrapolated"
    sign_band: float | None = None
    sign_band_relative: float | None = None
    tolerance: float = 1e-6
    max_iterations: int = 20
    law: str = "paper"

    def __post_init__(self) -> None:
        if not isinstance(self.coupling, str) or self.coupling not in COUPLINGS:
            raise SceneError(f"`coupling` must be one of {list(COUPLINGS)}, got {self.coupling!r}")
        if not isinstance(self.law, str) or self.law not in FRICTION_LAWS:
            raise SceneError(f"`law` must be one of {list(FRICTION_LAWS)}, got {self.law!r:.80}")
        if self.sign_band is not None and self.sign_band_relative is not None:
            raise SceneError(
                f"give either `sign_band` (absolute, m/s) or `sign_band_relative` (fraction of each "
                f"pair's speed), not both; got {self.sign_band!r} and {self.sign_band_relative!r}")
        for name in ("sign_band", "sign_band_relative"):
            if getattr(self, name) is not None:
                set_field(self, name, non_negative(name, getattr(self, name)))
        tol = positive("tolerance", self.tolerance)
        if tol >= 1.0:
            raise SceneError(f"`tolerance` must be < 1, got {tol!r}")
        set_field(self, "tolerance", tol)
        if (isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int)
                or not 2 <= self.max_iterations <= MAX_ITERATIONS):
            raise SceneError(f"`max_iterations` must be an integer in [2, {MAX_ITERATIONS}], "
                             f"got {self.max_iterations!r:.40}")

    @property
    def relative_band(self) -> float | None:
        """The relative ramp width in effect [-]: ``sign_band_relative``, its default, or None when
        ``sign_band`` is given.
        """
        if self.sign_band is not None:
            return None
        return DEFAULT_SIGN_BAND_RELATIVE if self.sign_band_relative is None else self.sign_band_relative


@dataclass(frozen=True)
class Record:
    """What to record.

    Attributes
    ----------
    timeseries : bool
        Return the time table (False: only the summary).
    every : int
        Keep every n-th step in the table (the summary always uses every step).
    skip_revolutions : float
        Input revolutions at the start excluded from the means [-], >= 0.
    """

    timeseries: bool = True
    every: int = 1
    skip_revolutions: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.timeseries, bool):
            raise SceneError(f"`timeseries` must be true or false, got {self.timeseries!r}")
        if isinstance(self.every, bool) or not isinstance(self.every, int) \
                or not 1 <= self.every <= MAX_STEPS:
            raise SceneError(f"`every` must be an integer in [1, {MAX_STEPS}], got {self.every!r:.40}")
        set_field(self, "skip_revolutions", non_negative("skip_revolutions", self.skip_revolutions))
