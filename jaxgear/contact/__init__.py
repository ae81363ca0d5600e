"""The coupled model's contact layer: the lubricated contacts of a mesh cycle, by friction rung."""

from .base import LOADED_SHARE as LOADED_SHARE
from .base import SIGN_SLIDE_TO_ROLL as SIGN_SLIDE_TO_ROLL
from .base import ContactForces as ContactForces
from .base import interface_from_forces as interface_from_forces
from .base import kinematic_velocities as kinematic_velocities
from .cycle import contact_forces as contact_forces
from .ehl import ehl_contact_forces as ehl_contact_forces
from .ehl import ehl_model_of as ehl_model_of
from .formula import formula_contact_forces as formula_contact_forces
from .formula import formula_ehl_contact_forces as formula_ehl_contact_forces
from .frozen import frozen_contact_forces as frozen_contact_forces
