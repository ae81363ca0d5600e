"""The fidelity ladder (``ladder.py``) and the choice of its cheapest rungs for a scenario
(``choose.py``)."""

from .choose import FidelityChoice as FidelityChoice
from .choose import ScenarioIndicators as ScenarioIndicators
from .choose import auto_fidelity as auto_fidelity
from .choose import choose_fidelity as choose_fidelity
from .choose import scenario_indicators as scenario_indicators
from .ladder import CONSTANTS as CONSTANTS
from .ladder import COUPLING_RUNGS as COUPLING_RUNGS
from .ladder import DYNAMICS_RUNGS as DYNAMICS_RUNGS
from .ladder import FLAT_FIELDS as FLAT_FIELDS
from .ladder import FRICTION_RUNGS as FRICTION_RUNGS
from .ladder import NAMED_PRESETS as NAMED_PRESETS
from .ladder import ContactConstants as ContactConstants
from .ladder import ContactModel as ContactModel
from .ladder import CoupledDynamics as CoupledDynamics
from .ladder import Fidelity as Fidelity
from .ladder import Resolution as Resolution


def _auto(cls, pair, lubricant, surfaces, op, tolerance: float = 0.05, **options) -> Fidelity:
    """The cheapest rungs whose measured error stays under ``tolerance`` for this scenario.

    Logic, options and the measured table: ``jaxgear.fidelity.choose``; ``jg.choose_fidelity``
    (same arguments) returns the reasons too. ``base=Fidelity(...)`` keeps that Fidelity's fields
    other than the ladder's (μb, shear law, asperity constants, fixed-point settings); by default
    they are ``Fidelity()``'s."""
    del cls
    return auto_fidelity(pair, lubricant, surfaces, op, tolerance, **options)


# The chooser sits above the ladder (it imports it); the ladder's class gets its ``auto`` here,
# so that ``Fidelity.auto(...)`` works without the ladder importing its chooser.
Fidelity.auto = classmethod(_auto)
