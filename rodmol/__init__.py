"""rodmol: dynamics of soft cable-driven continuum arms as Cosserat rods.

Implements and extends Renda et al., "Dynamic Model of a Multibending Soft
Robot Arm Driven by Cables", IEEE T-RO 30(5), 2014. SI units throughout.
"""

from . import scenarios
from .analysis import energy, marker_errors
from .arm import paper_arm
from .backends import BACKENDS
from .base import Base
from .cables import Cable, read_tension_csv
from .equilibrium import equilibrium
from .errors import EquilibriumError, IntegrationError, ParameterError, RodmolError
from .layout import StateLayout
from .markers import Marker
from .model import Model
from .parameters import MEDIA, Material, Medium
from .result import Result, load_result
from .rod import Rod
from .scenario_file import ScenarioError, load_scenario
from .semidiscrete import SemiDiscrete, StateView
from .simulate import default_atol, simulate, straight_state
from .writers import write_series

__version__ = "0.1.0"

__all__ = [
    "BACKENDS", "Base", "Cable", "EquilibriumError", "IntegrationError", "MEDIA", "Marker",
    "Material", "Medium", "Model", "ParameterError", "Result", "Rod", "RodmolError",
    "ScenarioError", "SemiDiscrete", "StateLayout", "StateView", "default_atol", "energy",
    "equilibrium", "load_result", "load_scenario", "marker_errors", "paper_arm",
    "read_tension_csv", "scenarios", "simulate", "straight_state", "write_series",
]
