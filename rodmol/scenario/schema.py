"""The schema of scenario files: the tables, their keys and the keys' units.

Documented in ``docs/scenario-reference.md``; the checks live in
:mod:`rodmol.scenario.problems` (the machinery) and the section readers
(:mod:`rodmol.scenario.arm`, :mod:`rodmol.scenario.loads`,
:mod:`rodmol.scenario.build`).
"""

import inspect

from ..loads import SCENARIO_TYPES


def _arguments(build):
    """(argument names, those without a default) of a load's constructor."""
    params = [p for p in inspect.signature(build).parameters.values() if not p.name.startswith("_")]
    return (tuple(p.name for p in params),
            tuple(p.name for p in params if p.default is inspect.Parameter.empty))


TOP = ("name", "description", "arm", "scenario", "gravity", "rod", "material", "medium",
       "cable", "marker", "load", "base", "discretization", "solver", "output")
ROD = ("length", "radius")
MATERIAL = ("E", "nu", "G", "mu", "rho", "viscosity")
#: Keys of [material] that are always required (and exactly one of nu, G).
MATERIAL_REQUIRED = ("E", "mu", "rho")
COEFFICIENTS = ("rho", "Cx", "Cy", "Cz", "By", "Bz")
SWITCHES = ("drag", "added_mass", "munk_moment")
DRAG_LAW = ("drag_law", "drag_coefficients")
MEDIUM = ("preset",) + COEFFICIENTS + SWITCHES + DRAG_LAW
CABLE = ("name", "offset", "anchor", "tension", "outside_body", "displacement", "compliance",
         "base_to_actuator", "rest_length", "friction", "slip_speed")
PAPER_CABLE = ("number", "tension")
MARKER = ("name", "s", "offset")
BASE = ("fixed", "position", "rotation", "velocity", "angular_velocity")
DISCRETIZATION = ("n_elements", "scheme")
SOLVER = ("backend", "rtol", "atol", "t_end", "output_dt", "initial", "max_wall_time")
OUTPUT = ("directory", "format", "vtk", "npz", "every", "chunk_frames")
ARMS = ("paper",)
INITIAL = ("equilibrium", "straight")
UNITS = {"length": "m", "radius": "m", "E": "Pa", "G": "Pa", "mu": "Pa s", "rho": "kg/m^3",
         "anchor": "m", "s": "m", "t_end": "s", "output_dt": "s", "max_wall_time": "s", "offset": "m", "tension": "N",
         "viscosity": "Pa s", "displacement": "m", "compliance": "1/N", "base_to_actuator": "m",
         "rest_length": "m", "friction": "-", "slip_speed": "m/s", "drag_coefficients": "kg/m^2"}

# --------------------------------------------------------------------------- [[load]]

#: [[load]] types: type -> (keys besides `type`, required keys), the
#: arguments of the constructors in :data:`rodmol.loads.SCENARIO_TYPES`.
LOADS = {kind: _arguments(build) for kind, (build, _) in SCENARIO_TYPES.items()}
#: Units of the [[load]] keys, by type.
LOAD_UNITS = {kind: units for kind, (_, units) in SCENARIO_TYPES.items()}
