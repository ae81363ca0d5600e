"""Sweeps of the coupled model over speeds and other inputs: the user API (``api.py``: ``sweep``,
``SweepResult``) on a chunked, resumable engine (``engine.py``: parallel or continuation, per-point
status, checkpoints)."""

from .api import POINT_STATUS_NAMES as POINT_STATUS_NAMES
from .api import SWEEPABLE as SWEEPABLE
from .api import SweepResult as SweepResult
from .api import sweep as sweep
