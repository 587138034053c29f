"""The ``lagged`` friction coupling (the paper's): the law on each step's reactions and speeds acts
during the next step; never a repeated solve. First order in the step; a loop gain >= 1 shows as
geometric growth of the friction, which stops the run."""

from __future__ import annotations

from typing import Any

from cardan_exudyn.model.coupling import FrictionCoupling
from reference.results.summary import Status

__all__ = ["LaggedCoupling"]


class LaggedCoupling(FrictionCoupling):
    """The friction of each step's solve applied in the next step."""

    iterates = False

    def initialise(self, solver: Any, settings: Any) -> None:
        """Friction consistent with the initial state (it acts in the first step)."""
        self.consistent_start(solver, settings)

    def post_newton(self, mbs: Any, t: float) -> list[float]:
        """Exudyn's post-Newton user function at ``t`` [s]: :meth:`update`'s ``[error, -1]``, an
        exception kept."""
        try:
            return self.update(t)
        except Exception as exc:  # process boundary with Exudyn's C++ loop: re-raised after it
            return self.failed(exc)

    def update(self, t: float) -> list[float]:
        """After the solve at ``t`` [s]: the law on its state, applied in the next step; ``[0, -1]``."""
        self.new_step(t)
        friction = self.evaluate(t)
        size = max(map(abs, friction))
        if self.grown(size):
            self.status = Status.SELF_LOCKING
            self.reason = self.growth_reason()
        self.apply(friction, size)
        return [0.0, -1.0]
