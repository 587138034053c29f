"""The Exudyn model of the RCCC Cardan joint; :mod:`~cardan_exudyn.model.accuracy` is the engine's
``run``. Run scenes through :func:`cardan_exudyn.run`, not through this package."""

__all__ = ["accuracy", "stepsize", "solve", "richardson", "error_estimate", "build", "options",
           "postprocess", "friction_law", "friction_io", "coupling", "extrapolated", "converged",
           "lagged", "rotations", "projection"]
