"""The tables of a scenario file, derived from the constructors they call.

Each table's keys, required keys and defaults are the parameters of the
rodmol constructors it feeds (their signatures); what the signatures cannot
say is written here once: the file's own keys (``preset``, ``fixed``,
``number``, ``type``...), the units shown in messages and in the reference,
and the few conversions from TOML (a file name relative to the scenario, a
constant velocity made a function of t). The reader
(:mod:`rodmol.scenario.build`), :mod:`rodmol.calibrate.variants` and the
test of ``docs/scenario-reference.md`` all read these records.

A new constructor parameter is a new key with no entry here (one in
:data:`UNITS` to show its unit); a new load kind is its record in
:data:`rodmol.loads.SCENARIO_TYPES`.
"""

import inspect
import os
from dataclasses import dataclass
from pathlib import Path

from .. import model_variants
from ..arm import paper_arm
from ..base_motion import BaseMotion
from ..bodies import BODY_CONTACT_UNITS, RigidBody
from ..cables import Cable
from ..contacts import Contact
from ..inputs import as_time_input
from ..loads import CONTACT_TYPES, SCENARIO_TYPES
from ..markers import Marker
from ..model import Model
from ..output.options import OutputOptions
from ..parameters import Material, Medium
from ..rod import Rod
from ..rod_contacts import RodContact
from ..simulate import simulate
from ..systems import Joint, System

#: Units of the keys [SI], by name (a [[load]] type's own come from its record).
UNITS = {"length": "m", "radius": "m", "E": "Pa", "G": "Pa", "mu": "Pa s", "rho": "kg/m^3",
         "viscosity": "Pa s", "anchor": "m", "s": "m", "offset": "m", "tension": "N",
         "displacement": "m", "compliance": "1/N", "base_to_actuator": "m", "rest_length": "m",
         "friction": "-", "slip_speed": "m/s", "drag_coefficients": "kg/m^2", "gravity": "m/s^2",
         "position": "m", "velocity": "m/s", "angular_velocity": "rad/s", "t_end": "s",
         "output_dt": "s", "max_wall_time": "s", "rest_curvature": "1/m", "rest_stretch": "-",
         "mass": "kg", "inertia": "kg m^2", "volume": "m^3", "centre_of_mass": "m", "density": "kg/m^3",
         "contact_points": "m", "contact_radius": "m"}

#: Keys whose value may name a file (CSV table), relative to the scenario file.
FILE_KEYS = ("tension", "displacement", "force", "moment", "directory", "mesh")
#: Keys whose constructor takes a function of t: the file gives what
#: :func:`rodmol.inputs.as_time_input` accepts (3 numbers, knots, a CSV file).
TIME_FUNCTIONS = ("velocity", "angular_velocity")


@dataclass(frozen=True)
class Source:
    """The parameters of ``build`` a table gives: all but ``skip``, or ``only`` those."""

    build: object
    only: tuple = None
    skip: tuple = ()

    def parameters(self):
        params = inspect.signature(self.build).parameters.values()
        return {p.name: p for p in params
                if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and not p.name.startswith("_")
                and p.name not in self.skip and (self.only is None or p.name in self.only)}


@dataclass(frozen=True)
class Table:
    """One table of a scenario file: the parameters of its ``sources`` (their
    defaults the constructors'), the file's own keys ``own`` (read by the
    reader itself) and the ``units`` of its keys (default :data:`UNITS`)."""

    sources: tuple
    own: tuple = ()
    units: dict = None

    def parameters(self):
        """{key: inspect.Parameter} of the keys the constructors take."""
        out = {}
        for source in self.sources:
            out.update(source.parameters())
        return out

    def names(self):
        """Every key the table allows, the file's own first."""
        return tuple(self.own) + tuple(self.parameters())

    def required(self):
        """The keys without a default in their constructor."""
        return tuple(k for k, p in self.parameters().items() if p.default is p.empty)

    def default(self, key):
        """The constructor's default of ``key`` (``inspect.Parameter.empty`` if required)."""
        return self.parameters()[key].default

    def unit(self, key):
        """The unit of ``key`` for messages and the reference, or None."""
        return (self.units or UNITS).get(key)

    def numbers(self):
        """The keys whose parameter is a number (annotated ``float``, or a float default)."""
        return tuple(k for k, p in self.parameters().items()
                     if "float" in str(p.annotation) or type(p.default) is float)

    def switches(self):
        """The keys whose parameter is a switch (a bool default)."""
        return tuple(k for k, p in self.parameters().items() if type(p.default) is bool)


# Model's keywords set in [medium] and simulate's a [solver] table sets (the others are Python's or the
# command line's): the overrides' module owns them, which sits below the scenario reader.
MODEL_SWITCHES, SOLVER_KEYS = model_variants.MODEL_SWITCHES, model_variants.SOLVER_KEYS

ROD = Table((Source(Rod, skip=("material",)),))
MATERIAL = Table((Source(Material),))
MEDIUM = Table((Source(Medium), Source(Model, only=MODEL_SWITCHES)), own=("preset",))
CABLE = Table((Source(Cable),))
PAPER_CABLE = Table((Source(Cable, only=("tension",)),), own=("number",))
MARKER = Table((Source(Marker),))
BASE = Table((Source(BaseMotion),), own=("fixed",))
#: (n_elements: the Model's; its default, paper_arm's.)
DISCRETIZATION = Table((Source(paper_arm, only=("n_elements",)), Source(simulate, only=("scheme",))))
SOLVER = Table((Source(simulate, only=SOLVER_KEYS),))
OUTPUT = Table((Source(OutputOptions),))
#: The [[load]] tables, by ``type``.
LOADS = {kind: Table((Source(build),), own=("type",), units=units)
         for kind, (build, units) in SCENARIO_TYPES.items()}

#: A system file's tables: [system] (its medium, a name or a table as
#: [medium], and gravity), [[rod]] (a rod's keys, its name and grid, and its
#: own [material], [[cable]], [[marker]], [[load]] and [base] nested),
#: [[body]] (a RigidBody, or one filling a mesh of a given density, its
#: [[body.contact]] obstacles), [[joint]] and [[contact]] (rods touching a body).
SYSTEM = Table((Source(System, only=("medium", "gravity")),))
SYSTEM_ROD = Table((Source(Rod, skip=("material",)), Source(Model, only=("n_elements",))),
                   own=("name", "material", "cable", "marker", "load", "base"))
BODY = Table((Source(RigidBody, skip=("contacts",)), Source(RigidBody.from_mesh, only=("density",))),
             own=("name", "contact"))
#: A body's ``[[body.contact]]`` tables (its ``contacts``), by ``type``: the contact
#: [[load]] types, their law per contact point.
BODY_CONTACTS = {kind: Table(LOADS[kind].sources, own=("type",), units={**LOADS[kind].units, **BODY_CONTACT_UNITS})
                 for kind in CONTACT_TYPES}
#: A system file's ``[[contact]]`` tables (a :class:`rodmol.Contact` each), by
#: ``type``: the contact [[load]] types, in the body frame (the System names
#: the shape), with the contact's ``body`` and ``rods``.
CONTACTS = {kind: Table((Source(LOADS[kind].sources[0].build, skip=("name",)), Source(Contact, only=("body", "rods"))),
                        own=("type",), units=LOADS[kind].units)
            for kind in CONTACT_TYPES}
#: The ``[[contact]]`` type of rods touching rods (:class:`rodmol.RodContact`: ``a``, ``b`` and its law).
ROD_CONTACT_TYPE = "rods"
CONTACTS[ROD_CONTACT_TYPE] = Table((Source(RodContact),), own=("type",),
                                   units={"stiffness": "N/m^2", "damping": "N s/m^2", "smoothing_depth": "m"})
#: A driven body's ``motion`` table (its position and rotation are the body's).
BODY_MOTION = Table((Source(BaseMotion, only=("velocity", "angular_velocity")),))
JOINT = Table((Source(Joint),))
#: The tables of a system file only.
SYSTEM_TABLES = ("system", "body", "joint", "contact")

#: The tables, by name (``[[...]]`` arrays of tables: cable, marker, load, body, joint,
#: contact; in a system file, rod too, as :data:`SYSTEM_ROD`). load and contact: by type.
TABLES = {"rod": ROD, "material": MATERIAL, "medium": MEDIUM, "cable": CABLE, "marker": MARKER,
          "load": None, "base": BASE, "discretization": DISCRETIZATION, "solver": SOLVER,
          "output": OUTPUT, "system": SYSTEM, "body": BODY, "joint": JOINT, "contact": None}
ARRAYS = ("cable", "marker", "load", "body", "joint", "contact")
TOP = Table((Source(Model, only=("gravity",)),), own=("name", "description", "arm", "scenario")
            + tuple(TABLES))
ARMS = ("paper",)


def table_of(key):
    """The path of the table (not an array of tables) whose key ``key`` is,
    for placing a Model's errors; None if none."""
    for name, table in (("", TOP), *TABLES.items()):
        if table is not None and name not in ARRAYS and key in table.parameters():
            return (name,) if name else ()
    return None


def convert(key, value, base_dir):
    """A TOML value as the constructor takes it: arrays as tuples, a file name
    relative to ``base_dir``, a time function of the values of
    :data:`TIME_FUNCTIONS`. The constructor checks the result."""
    value = _tuples(value)
    if key in FILE_KEYS and isinstance(value, str):
        return Path(os.path.normpath(Path(base_dir) / value))  # (an absolute value stays)
    if key in TIME_FUNCTIONS:
        # A bound method of the time input, not a closure, so that the model pickles.
        return as_time_input(key, value, 3, UNITS[key]).value
    return value


def _tuples(value):
    if isinstance(value, list):
        return tuple(_tuples(v) for v in value)
    if isinstance(value, dict):
        return {k: _tuples(v) for k, v in value.items()}
    return value
