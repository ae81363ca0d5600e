"""Isothermal smooth line-contact EHL: steady and one-step transient, Newtonian or Eyring, with
implicit gradients.

Method (EHL_NOTES, REFERENCE §8): Hertz-scaled variables; unknowns P at the N nodes and the film
offset H0, with the load balance Δ Σ P = π/2 as the extra row of a bordered Newton system;
cavitation as a smoothed Fischer-Burmeister complementarity (``reynolds.py``); exact log-kernel
deformation (``deformation.py``). The Jacobian is assembled exactly: the local (banded)
derivatives of the Reynolds operator with respect to P and H come from 8 forward-mode products
with coloured seeds, the dense part is the banded H-derivative times the influence matrix.
Robustness across the (M, L) range comes from continuation in the piezo-viscous exponent on the
coarsest grid, coarse-to-fine grid sequencing, and a backtracking line search on the residual
norm; every loop is a ``lax.while_loop``/``lax.scan``. A failed solve reports ``converged=False``
with its residual and finite values, never NaN.

Gradients: the converged fine-grid solution u*(θ) of F(u, θ) = 0 is differentiated by the implicit
function theorem, du = −(∂F/∂u)⁻¹ (∂F/∂θ) dθ (a ``jax.custom_jvp``; reverse mode transposes it),
never through the iterations.

Outputs follow S. Li, Tribol. Int. 88 (2015): heat flux Eq. (12), damping Eq. (13), friction Eq.
(15).

Modules, each importing only those above it:

- ``model``: the inputs (``LineContact``, ``EHLModel`` and its choices, ``_Inputs``);
  ``solution``: the result (``EHLSolution``).
- ``discretisation``: the dimensionless problem on a grid (``_Level``) and the films a transient
  step reads.
- ``newton``: Newton with backtracking and its linear solves (dense LU, GMRES).
- ``starts``: cold and warm starts, relaxation sweeps; ``continuation``: the continuations on the
  finest grid (exponent, roughness, temperatures, pseudo-time).
- ``core``: the differentiable solve (``_solve_core``, implicit derivative) and its SI outputs.
- ``outer``: the thermal iteration around it (``_solve_impl``).
- ``solve``: ``solve_ehl``.
"""

from .continuation import SETTLE_CHANGE as SETTLE_CHANGE
from .discretisation import hertz_film_scale as hertz_film_scale
from .discretisation import moes_central_film as moes_central_film
from .discretisation import transport_shift as transport_shift
from .model import COMPRESSIBILITY_MODELS as COMPRESSIBILITY_MODELS
from .model import DEFORMATION_METHODS as DEFORMATION_METHODS
from .model import LINEAR_SOLVERS as LINEAR_SOLVERS
from .model import MIXED_MODELS as MIXED_MODELS
from .model import MODEL_NUMBERS as MODEL_NUMBERS
from .model import SHEAR_MODELS as SHEAR_MODELS
from .model import TIME_SCHEMES as TIME_SCHEMES
from .model import TRANSPORT_SCHEMES as TRANSPORT_SCHEMES
from .model import VISCOSITY_MODELS as VISCOSITY_MODELS
from .model import EHLModel as EHLModel
from .model import LineContact as LineContact
from .solution import EHLSolution as EHLSolution
from .solve import solve_ehl as solve_ehl
