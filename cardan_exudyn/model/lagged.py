"""The ``lagged`` friction coupling (the paper's scheme): the friction one step late.

After each step's single Newton solve the law is evaluated on that step's reactions and speeds,
and the friction acts during the next step; the post-Newton function returns zero error, so
Exudyn never repeats a solve. First order in the step (the friction is one step late). Every step
is one iteration of the friction feedback's map, so a loop gain >= 1 shows as geometric growth of
the friction, which stops the run (:meth:`~cardan_exudyn.model.coupling.FrictionCoupling.grown`).
"""

from __future__ import annotations

from typing import Any

from cardan_exudyn.model.coupling import FrictionCoupling
from reference.results.summary import Status

__all__ = ["LaggedCoupling"]


class LaggedCoupling(FrictionCoupling):
    """The friction of each step's solve applied in the next step."""

    iterates = False

    def initialise(self, solver: Any, settings: Any) -> None:
        """Friction consistent with the initial state (it acts in the first step).

        Parameters
        ----------
        solver : exudyn.MainSolverImplicitSecondOrder
            Initialised (``solver.InitializeSolver`` called).
        settings : exudyn.SimulationSettings
            The run's settings.
        """
        self.consistent_start(solver, settings)

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function: :meth:`update`, an exception kept
        (:meth:`~cardan_exudyn.model.coupling.FrictionCoupling.failed`).

        Parameters
        ----------
        mbs : exudyn MainSystem
            The system just solved.
        t : float
            Time of the solve [s].

        Returns
        -------
        list of float
            Exudyn's ``[error, -1]``: a positive error repeats the step's solve.
        """
        try:
            return self.update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            return self.failed(exc)

    def update(self, t: float) -> list[float]:
        """After the solve of the step at ``t`` [s]: the law on its state, applied from now on;
        the error ``[0, -1]`` (Exudyn never repeats the solve)."""
        self.new_step(t)
        friction = self.evaluate(t)
        size = max(map(abs, friction))
        if self.grown(size):
            self.status = Status.SELF_LOCKING
            self.reason = self.growth_reason()
        self.apply(friction, size)
        return [0.0, -1.0]
