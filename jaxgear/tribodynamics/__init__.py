"""The thermal tribo-dynamic model: gear dynamics and the lubricated contacts solved together."""

from .fixed_point import Pending as Pending
from .fixed_point import WarmStart as WarmStart
from .fixed_point import cold_start as cold_start
from .passes import check_inputs as check_inputs
from .passes import first_pass as first_pass
from .passes import needs_second_pass as needs_second_pass
from .passes import simulate as simulate
from .passes import simulate_with_state as simulate_with_state
from .result import STATUS_ATTRACTOR as STATUS_ATTRACTOR
from .result import STATUS_CONTACT as STATUS_CONTACT
from .result import STATUS_DYNAMICS as STATUS_DYNAMICS
from .result import STATUS_FIXED_POINT as STATUS_FIXED_POINT
from .result import STATUS_NAMES as STATUS_NAMES
from .result import STATUS_NON_FINITE as STATUS_NON_FINITE
from .result import STATUS_OK as STATUS_OK
from .result import STATUS_PENDING as STATUS_PENDING
from .result import SimulationResult as SimulationResult
from .second_pass import ATTRACTOR_CONTACT_CYCLES as ATTRACTOR_CONTACT_CYCLES
from .second_pass import ATTRACTOR_WARM_SETTLE as ATTRACTOR_WARM_SETTLE
from .second_pass import finish as finish
