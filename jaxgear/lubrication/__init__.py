"""Lubrication: rheology, roughness, thermal kernels, friction models and the EHL solver."""

from .ehl import EHLModel as EHLModel
from .ehl import EHLSolution as EHLSolution
from .ehl import LineContact as LineContact
from .ehl import solve_ehl as solve_ehl
from .lubricant import Lubricant as Lubricant
