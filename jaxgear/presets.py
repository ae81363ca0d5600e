"""Presets: the paper's gear pair, materials, lubricants, surfaces (REFERENCE §2, §4, §6)."""

from __future__ import annotations

import math

from .gear.pair import Bearings, GearPair, TipRelief
from .lubrication.lubricant import iso_vg68 as iso_vg68
from .lubrication.lubricant import mil_l_23699 as mil_l_23699
from .lubrication.roughness import ground as ground
from .lubrication.roughness import polished as polished
from .lubrication.roughness import smooth as smooth
from .material import steel as steel


def li2015_pair(tip_relief: float = 10e-6, relief_start_deg: float = 20.9) -> GearPair:
    """The paper's spur gear pair (REFERENCE §2) by its basic rack: 50/50 teeth, m 3 mm, 20°,
    h_a* = 1, h_f* = 5/3, no profile shift, face 20 mm, backlash 0.14 mm, the paper's bearings,
    linear tip relief of ``tip_relief`` metres on both gears from roll angle ``relief_start_deg``.

    The tip and root diameters 156/140 mm and the centre distance 150 mm are derived from these
    (to round-off), so a changed module or pressure angle gives a consistent pair. Blanks default to
    solid steel disks (the paper does not give masses); see ``li2015_pair_calibrated`` for the preset
    tuned to the paper's resonance speeds.
    """
    return GearPair(
        teeth=(50, 50),
        module=3.0e-3,
        pressure_angle=math.radians(20.0),
        face_width=0.020,
        addendum_coefficient=1.0,
        dedendum_coefficient=5.0 / 3.0,  # root diameter 140 mm = m (z − 2 h_f*)
        backlash=0.14e-3,
        bearings=Bearings(ky=1.15e9, cy=5360.0, kx=8.0e8, cx=2980.0, ct=10.0),
        tip_relief=TipRelief(
            amount=tip_relief, start_roll_angle=math.radians(relief_start_deg), shape="linear"
        ),
    )


# Blanks of the calibrated preset (notebooks/calibration.ipynb): one mesh-coupled mode at 3500 rpm of
# mesh excitation (2916.7 Hz), the other below the sweep at 400 rpm, with the mean mesh stiffness
# 3.11e8 N/m of li2015_pair() at 700 N m, the paper's bearings and equal gears.
LI2015_CALIBRATED_BLANK_MASS = 5.316  # kg, per gear
LI2015_CALIBRATED_BLANK_INERTIA = 0.4540  # kg m², per gear


def li2015_pair_calibrated(tip_relief: float = 10e-6, relief_start_deg: float = 20.9) -> GearPair:
    """``li2015_pair`` with blanks calibrated to the paper's DTE-RMS peaks (REFERENCE §6, §7 R1).

    Blank mass 5.316 kg and inertia 0.454 kg m² per gear (the test rig's effective translating mass
    on the bearings and rotary inertia of gear, shaft and coupling; solid disks would be 2.77 kg and
    7.8e-3 kg m²). With them the linearised model has its dominant mesh-coupled mode at 3500 rpm of
    mesh excitation and the other one at 400 rpm, below the sweep; the stepwise-increasing sweep at
    700 N m then peaks at 1750 rpm (the 2nd-mesh-harmonic super-harmonic of the 3500 rpm mode) and,
    larger, around 3500 rpm, as in the paper. The mesh stiffness is not scaled. How and why (and the
    alternative two-mode reading, which the model does not support): notebooks/calibration.ipynb.
    """
    return li2015_pair(tip_relief=tip_relief, relief_start_deg=relief_start_deg).replace(
        blank_mass=LI2015_CALIBRATED_BLANK_MASS, blank_inertia=LI2015_CALIBRATED_BLANK_INERTIA
    )
