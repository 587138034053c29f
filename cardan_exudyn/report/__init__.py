"""What every report shares: :mod:`~cardan_exudyn.report.format` (number and markdown table
formatter, also the CLI's), :mod:`~cardan_exudyn.report.plots` (data in, Figure out) and
:mod:`~cardan_exudyn.report.environment` (versions, CPU, date, commit). Import the submodules by
name; importing this package imports none of them (``plots`` loads matplotlib).
"""

__all__ = ["environment", "format", "plots"]
