"""rodmol: dynamics of soft cable-driven continuum arms as Cosserat rods.

Implements and extends Renda et al., "Dynamic Model of a Multibending Soft
Robot Arm Driven by Cables", IEEE T-RO 30(5), 2014. SI units throughout.

The package follows the data flow. The user's nouns are flat at the top:
parameters, rod, cables, base motion, loads, markers, model, simulate,
result, analysis. The machinery sits in folders: ``discretise/`` (state
layout, the compiled physics and the semi-discrete scheme, its Jacobian),
``solve/`` (static equilibrium and the time-integration backends),
``output/`` (run directories, ParaView views and series, the formats' table,
pictures), ``scenario/`` (TOML scenario files), ``cli/`` (the command line),
``calibrate/`` (measured data, stereo reconstruction, the paper's error
study, identification, sweeps, linearisation) and ``control/`` (the stepping
simulator, inverse statics; the gymnasium environments in ``rodmol.control.envs``).
"""

from . import scenarios
from ._version import __version__ as __version__
from .analysis import energy, marker_errors, oscillation_period
from .arm import paper_arm
from .base_motion import Base, BaseMotion
from .bodies import RigidBody
from .cables import Cable, read_tension_csv
from .calibrate import (
    LinearModel,
    calibrate_dlt,
    identify,
    linearize,
    paper_errors,
    sweep,
    triangulate,
    worsened_models,
)
from .calibrate.marker_loss import MarkerTracking
from .contacts import Contact
from .control import (
    Simulator,
    StaticFit,
    SystemFit,
    TensionPlan,
    inverse_statics,
    inverse_statics_path,
    optimal_tensions,
)
from .discretise.layout import StateLayout
from .discretise.schemes import SCHEMES
from .discretise.system import SemiDiscrete, StateView, straight_state, undeformed_state
from .errors import (
    EquilibriumError,
    IntegrationError,
    NotSupportedYet,
    ParameterError,
    RodmolError,
    UserFunctionError,
)
from .gradients import gradient
from .loads import (
    CapsuleContact,
    DistributedForce,
    DistributedMoment,
    Hold,
    PlaneContact,
    PointForce,
    PointMoment,
    SphereContact,
)
from .losses import BodyAdvance, BodyTarget, Effort, StateLoss, TerminalTarget, TipTracking
from .markers import Marker
from .model import Model
from .output.formats import load_result, write_series
from .parameters import MEDIA, Material, Medium
from .result import Result
from .rod import Rod
from .rod_contacts import RodContact
from .scenario.file import ScenarioError, load_scenario
from .simulate import default_atol, simulate
from .solve.backends import BACKENDS
from .solve.equilibrium import equilibrium
from .systems import Joint, System

__all__ = [
    "BACKENDS", "Base", "BaseMotion", "Cable", "CapsuleContact", "Contact", "DistributedForce",
    "DistributedMoment", "Hold", "PlaneContact", "PointForce", "PointMoment", "SphereContact", "EquilibriumError", "IntegrationError", "MEDIA",
    "Joint", "Marker", "RodContact", "Material", "Medium", "Model", "NotSupportedYet", "RigidBody", "System", "ParameterError", "Result", "Rod", "RodmolError",
    "SCHEMES", "ScenarioError", "SemiDiscrete", "Simulator", "StateLayout", "StateView", "UserFunctionError",
    "default_atol", "energy",
    "equilibrium", "load_result", "load_scenario", "marker_errors", "oscillation_period", "paper_arm",
    "read_tension_csv", "scenarios", "simulate", "straight_state", "undeformed_state", "write_series",
    # rodmol.calibrate: from experiment to model
    "LinearModel", "calibrate_dlt", "identify", "linearize", "paper_errors", "sweep", "triangulate",
    "worsened_models",
    # rodmol.control: questions a controller asks
    "StaticFit", "SystemFit", "inverse_statics", "inverse_statics_path",
    # gradients of a run (docs/gradients.md)
    "BodyAdvance", "BodyTarget", "Effort", "MarkerTracking", "StateLoss", "TensionPlan", "TerminalTarget",
    "TipTracking", "gradient", "optimal_tensions",
]
