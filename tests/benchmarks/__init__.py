"""The project's own research tooling: benchmarks against targets, verification campaigns and the
studies behind constants of the product (``docs/benchmarks.md``). Not installed: run from a
source checkout with ``python tests/benchmarks NAME [options]``; the product never imports it.

Each benchmark is a module with ``register(subparsers)``, named in :data:`BENCHMARKS`.
"""

from __future__ import annotations

__all__ = ["BENCHMARKS"]

BENCHMARKS: dict[str, str] = {
    "targets": "benchmarks.targets.command",
    "batch": "benchmarks.batch.command",
    "longrun": "benchmarks.longrun.command",
    "accuracy": "benchmarks.accuracy.command",
    "coupling": "benchmarks.friction_numerics",
    "sign-band": "benchmarks.friction_numerics",
    "mujoco-settings": "benchmarks.mujoco_settings.command",
    "campaign-truth": "benchmarks.campaign.command",
    "campaign-coverage": "benchmarks.campaign.command",
    "campaign-groups": "benchmarks.campaign.command",
    "campaign-sampling": "benchmarks.campaign.command",
}
"""Benchmark name -> the module whose ``register(subparsers, name)`` adds it, in the order
``python tests/benchmarks --help`` lists them."""
