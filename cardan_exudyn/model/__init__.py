"""The Exudyn model of the RCCC Cardan joint.

- :mod:`~cardan_exudyn.model.accuracy`: the engine's ``run``: the runs a scene takes to meet its
  accuracy (pilot, companion, main run, refinement) and the estimate of their error;
- :mod:`~cardan_exudyn.model.stepsize`: the a-priori error model and the step it asks for;
- :mod:`~cardan_exudyn.model.solve`: one solve of a scene, its columns and summary;
- :mod:`~cardan_exudyn.model.richardson`: the Richardson combination of two runs (frictionless);
- :mod:`~cardan_exudyn.model.error_estimate`: the pytest plugin's error estimate of a finished
  run (step halving; the reference engine's quadrature);
- :mod:`~cardan_exudyn.model.build`: bodies, pairs (generic joints), drive, load and sensors of a
  scene, only what the scene needs;
- :mod:`~cardan_exudyn.model.options`: :class:`ExudynOptions`, the solver settings;
- :mod:`~cardan_exudyn.model.postprocess`: the result's columns from the sensors;
- :mod:`~cardan_exudyn.model.friction_law`: eqs. (1)-(5) as pure functions (no Exudyn);
- :mod:`~cardan_exudyn.model.coupling`: the friction loads and what every coupling scheme
  shares; the schemes :mod:`~cardan_exudyn.model.extrapolated` (the default),
  :mod:`~cardan_exudyn.model.converged` and :mod:`~cardan_exudyn.model.lagged`;
  :mod:`~cardan_exudyn.model.friction_io`: reading the reactions and setting the loads;
- :mod:`~cardan_exudyn.model.rotations`, :mod:`~cardan_exudyn.model.projection`: node rotation
  parameters, velocity projection.

Run scenes through :func:`cardan_exudyn.run` (the engine dispatch), not through this package.
"""

__all__ = ["accuracy", "stepsize", "solve", "richardson", "error_estimate", "build", "options",
           "postprocess", "friction_law", "friction_io", "coupling", "extrapolated", "converged",
           "lagged", "rotations", "projection"]
