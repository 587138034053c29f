"""The Exudyn model of the RCCC Cardan joint.

- :mod:`~cardan_exudyn.model.build`: bodies, pairs (generic joints), drive, load and sensors of a
  scene, only what the scene needs;
- :mod:`~cardan_exudyn.model.options`: :class:`ExudynOptions`, the solver settings;
- :mod:`~cardan_exudyn.model.solve`: the one solve sequence and the engine's ``run``;
- :mod:`~cardan_exudyn.model.postprocess`: the result schema's columns from the sensors;
- :mod:`~cardan_exudyn.model.friction_law`: eqs. (1)-(5) as pure functions (no Exudyn);
- :mod:`~cardan_exudyn.model.coupling`: the friction loads and the user functions that update
  them from the joint reactions;
- :mod:`~cardan_exudyn.model.rotations`, :mod:`~cardan_exudyn.model.projection`,
  :mod:`~cardan_exudyn.model.stepsize`: node rotation parameters, velocity projection, the
  automatic step.

Run scenes through :func:`cardan_exudyn.run` (the engine dispatch), not through this package.
"""

__all__ = ["build", "options", "solve", "postprocess", "friction_law", "coupling", "rotations",
           "projection", "stepsize"]
