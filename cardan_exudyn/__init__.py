"""The RCCC Cardan joint in Exudyn, the engine registry, result writers, reports and the CLI.

The only package of the project that imports exudyn.
"""
