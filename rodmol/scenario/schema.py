"""The schema of scenario files: the tables, their keys and the keys' units.

Documented in ``docs/scenario-reference.md``; the checks live in
:mod:`rodmol.scenario.problems` (the machinery) and the section readers
(:mod:`rodmol.scenario.arm`, :mod:`rodmol.scenario.loads`,
:mod:`rodmol.scenario.build`).
"""

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

FRAMES = ("global", "local")
CONTACT_LAW = ("stiffness", "damping", "friction", "slip_speed", "smoothing_depth")

#: [[load]] types: type -> (keys besides `type`, required keys). The keys are
#: the arguments of the Python classes of :mod:`rodmol.loads`.
LOADS = {
    "point_force": (("s", "force", "frame", "name"), ("s", "force")),
    "point_moment": (("s", "moment", "frame", "name"), ("s", "moment")),
    "distributed_force": (("force", "frame", "name"), ("force",)),
    "distributed_moment": (("moment", "frame", "name"), ("moment",)),
    "plane_contact": (("point", "normal") + CONTACT_LAW + ("name",), ("point", "normal", "stiffness")),
    "sphere_contact": (("centre", "radius") + CONTACT_LAW + ("name",), ("centre", "radius", "stiffness")),
    "capsule_contact": (("start", "end", "radius") + CONTACT_LAW + ("name",),
                        ("start", "end", "radius", "stiffness")),
}

#: Units of the [[load]] keys; ``force`` and ``moment`` depend on the type.
LOAD_UNITS = {"s": "m", "point": "m", "normal": "-", "centre": "m", "start": "m", "end": "m",
              "radius": "m", "stiffness": "N/m^2", "damping": "N s/m^2", "friction": "-",
              "slip_speed": "m/s", "smoothing_depth": "m"}
POINT_UNITS = {"force": "N", "moment": "N m"}
DISTRIBUTED_UNITS = {"force": "N/m", "moment": "N m/m"}
