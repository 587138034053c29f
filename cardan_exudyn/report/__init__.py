"""What every report shares: :mod:`~cardan_exudyn.report.format` (the one number and markdown
table formatter, also the CLI's) and :mod:`~cardan_exudyn.report.plots` (figure functions that
take data and return a Figure), :mod:`~cardan_exudyn.report.environment` (versions, CPU,
date and commit for the head of a results file). The reports themselves are written by the studies
(``cardan_exudyn/studies/*``) and :mod:`rigdata.report`.

The submodules are imported by name (``from cardan_exudyn.report.format import number``);
importing this package imports none of them (``plots`` loads matplotlib).
"""

__all__ = ["environment", "format", "plots"]
