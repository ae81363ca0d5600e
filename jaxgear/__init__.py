"""jaxgear: differentiable thermal tribo-dynamic power loss model of spur gear pairs in JAX.

Implements S. Li, "A thermal tribo-dynamic mechanical power loss model for spur gear pairs",
Tribology International 88 (2015) 170-178, and goes beyond it (implicit gradients, sweeps, fidelity
ladder). SI units inside. Enable float64 (``jax.config.update("jax_enable_x64", True)``) before use:
the library never changes ``jax.config`` itself.
"""

from . import paper as figures  # the former name of jaxgear.paper
from . import paper as paper
from . import presets as presets
from . import results as results
from . import units as units
from .gear.geometry import GearGeometry as GearGeometry
from .gear.geometry import gear_geometry as gear_geometry
from .gear.geometry import hertz_half_width as hertz_half_width
from .gear.geometry import hertz_pressure as hertz_pressure
from .gear.geometry import kinematics as kinematics
from .gear.mesh import MeshCycle as MeshCycle
from .gear.mesh import mesh_cycle as mesh_cycle
from .gear.pair import Bearings as Bearings
from .gear.pair import GearPair as GearPair
from .gear.pair import TipRelief as TipRelief
from .material import Material as Material

__version__ = "0.1.0"
from .design.calibrate import CalibrationResult as CalibrationResult
from .design.calibrate import calibrate as calibrate
from .design.pareto import ParetoFront as ParetoFront
from .design.pareto import pareto_front as pareto_front
from .design.sensitivity import SensitivityReport as SensitivityReport
from .design.sensitivity import sensitivity as sensitivity
from .design.tip_relief import DesignResult as DesignResult
from .design.tip_relief import optimise_tip_relief as optimise_tip_relief
from .dynamics import DynamicResponse as DynamicResponse
from .dynamics import DynamicsOptions as DynamicsOptions
from .dynamics import MeshInterface as MeshInterface
from .dynamics import Modes as Modes
from .dynamics import dynamic_response as dynamic_response
from .dynamics import dynamic_response_sweep as dynamic_response_sweep
from .dynamics import mode_shapes as mode_shapes
from .dynamics import natural_frequencies as natural_frequencies
from .fidelity import Fidelity as Fidelity
from .fidelity.choose import FidelityChoice as FidelityChoice
from .fidelity.choose import ScenarioIndicators as ScenarioIndicators
from .fidelity.choose import choose_fidelity as choose_fidelity
from .fidelity.choose import scenario_indicators as scenario_indicators
from .lubrication import thermal as thermal
from .lubrication.ehl import EHLModel as EHLModel
from .lubrication.ehl import EHLSolution as EHLSolution
from .lubrication.ehl import LineContact as LineContact
from .lubrication.ehl import solve_ehl as solve_ehl
from .lubrication.friction_models import ConstantFriction as ConstantFriction
from .lubrication.friction_models import FrictionModel as FrictionModel
from .lubrication.friction_models import XuFriction as XuFriction
from .lubrication.lubricant import Lubricant as Lubricant
from .lubrication.roughness import Surfaces as Surfaces
from .operating import OperatingPoint as OperatingPoint
from .optimise import OptimisationResult as OptimisationResult
from .optimise import optimise as optimise_bounded
from .optimise import optimise_roughness_scale as optimise_roughness_scale
from .optimise import optimise_torque as optimise_torque
from .results import Status as Status
from .sweep import SweepResult as SweepResult
from .sweep import sweep as sweep
from .tribodynamics import SimulationResult as SimulationResult
from .tribodynamics import simulate as simulate
