"""Presets: the paper's gear pair, materials, lubricants, surfaces (REFERENCE §2, §4, §6)."""

from __future__ import annotations

import math

from .gear.pair import Bearings, GearPair, TipRelief
from .material import steel as steel


def li2015_pair(tip_relief: float = 10e-6, relief_start_deg: float = 20.9) -> GearPair:
    """The paper's spur gear pair (REFERENCE §2): 50/50 teeth, m 3 mm, 20°, face 20 mm,
    tip/root diameter 156/140 mm, centre distance 150 mm, backlash 0.14 mm, the paper's bearings,
    linear tip relief of ``tip_relief`` metres on both gears from roll angle ``relief_start_deg``.

    Blanks default to solid steel disks (the paper does not give masses); see
    ``li2015_pair_calibrated`` for the preset tuned to the paper's resonance speeds.
    """
    m = 3.0e-3
    return GearPair(
        teeth=(50, 50),
        module=m,
        pressure_angle=math.radians(20.0),
        face_width=0.020,
        tip_radius=0.078,
        root_radius=0.070,
        centre_distance=0.150,
        backlash=0.14e-3,
        bearings=Bearings(ky=1.15e9, cy=5360.0, kx=8.0e8, cx=2980.0, ct=10.0),
        tip_relief=TipRelief(
            amount=tip_relief, start_roll_angle=math.radians(relief_start_deg), shape="linear"
        ),
    )


from .lubrication.lubricant import iso_vg68 as iso_vg68  # noqa: E402
from .lubrication.lubricant import mil_l_23699 as mil_l_23699  # noqa: E402
from .lubrication.roughness import ground as ground  # noqa: E402
from .lubrication.roughness import polished as polished  # noqa: E402
from .lubrication.roughness import smooth as smooth  # noqa: E402
