"""Gear dynamics: the 6-DOF model of paper Eq. (1), periodic steady state, DTE, sweeps and modes."""

from .attractor import AttractorRecord as AttractorRecord
from .attractor import attractor_response as attractor_response
from .model import DynamicsOptions as DynamicsOptions
from .model import GearDynamics as GearDynamics
from .model import MeshInterface as MeshInterface
from .model import backlash_exact as backlash_exact
from .model import backlash_smooth as backlash_smooth
from .modes import Modes as Modes
from .modes import mode_shapes as mode_shapes
from .modes import natural_frequencies as natural_frequencies
from .response import DynamicResponse as DynamicResponse
from .response import dte_harmonic_amplitudes as dte_harmonic_amplitudes
from .response import dynamic_response as dynamic_response
from .response import dynamic_response_sweep as dynamic_response_sweep
