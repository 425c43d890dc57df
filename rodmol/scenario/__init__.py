"""The scenario reader: one TOML file describes one run; :func:`load_scenario`
checks it and gives a :class:`rodmol.run_spec.RunSpec` (see :mod:`rodmol.scenario.file`)."""

from .file import Override, ScenarioError, load_scenario, parse_scenario

__all__ = ["Override", "ScenarioError", "load_scenario", "parse_scenario"]
