"""Physics every engine shares: Cardan and RCCC kinematics, joint motion, the friction law
(eqs. (1)-(5)), sign bands."""

from __future__ import annotations

from reference.lazy import lazy_face

_LAZY = {
    "PROFILE_SAMPLES": "reference.physics.bands",
    "SPEED_FLOOR": "reference.physics.bands",
    "PairBands": "reference.physics.bands",
    "PairSpeeds": "reference.physics.bands",
    "characteristic_speeds": "reference.physics.bands",
    "profile_angles": "reference.physics.bands",
    "speeds_from_profile": "reference.physics.bands",
    "needs_speeds": "reference.physics.bands",
    "bands_from_speeds": "reference.physics.bands",
    "nominal_speed": "reference.physics.bands",
    "sign_bands": "reference.physics.bands",
    "Dual": "reference.physics.dual",
    "as_dual": "reference.physics.dual",
    "sin": "reference.physics.dual",
    "cos": "reference.physics.dual",
    "atan2": "reference.physics.dual",
    "dot": "reference.physics.dual",
    "cross": "reference.physics.dual",
    "matvec": "reference.physics.dual",
    "matrix": "reference.physics.dual",
    "stack": "reference.physics.dual",
    "rot_x": "reference.physics.dual",
    "rot_z": "reference.physics.dual",
    "screw_transform": "reference.physics.dual",
    "line": "reference.physics.dual",
    "line_point": "reference.physics.dual",
    "displacement": "reference.physics.dual",
    "solve": "reference.physics.dual",
    "friction_from_columns": "reference.physics.friction",
    "friction_magnitudes": "reference.physics.friction",
    "pair_friction": "reference.physics.friction",
    "pair_power_loss": "reference.physics.friction",
    "regularised_sign": "reference.physics.friction",
    "slip_direction": "reference.physics.friction",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
