"""The paper's reported results and the settings of its runs (S. Li 2015; REFERENCE §2, §7): the
R1-R11 statements, the tribo-dynamic and quasi-static losses at points A-E, the points' nominal
speeds, the baseline and variant inputs, and the contact-field settings of Figs. 7 and 12."""

from __future__ import annotations

#: Figures of the paper this module reproduces (Fig. 9 is not described by REFERENCE §7).
FIGURES = (3, 4, 5, 6, 7, 8, 9, 10, 11, 12)

#: The paper's reported results, REFERENCE §7.
PAPER_RESULTS = {
    "R1": "(εd)rms peaks at 1750 rpm and 3500 rpm, the 3500 rpm peak much larger (Fig. 3)",
    "R2": "Φ̄ thermal tribo-dynamic at A, B, D, E = 257, 343, 431, 948 W; quasi-static = 276, 302, "
    "526, 532 W",
    "R3": "tribo-dynamic Φ̄ lower than quasi-static at A and D, higher at B and E, nearly equal at C",
    "R4": "efficiency Ψ within 99.6-99.85 % over the sweep (Fig. 4b)",
    "R5": "iso-thermal Φ̄ > thermal Φ̄, the gap growing with speed (Fig. 6)",
    "R6": "inlet 60 °C: lower Φ̄ and higher Ψ than 90 °C, ground surfaces (Fig. 8)",
    "R7": "1500 N m: Φ̄ much higher, Ψ only slightly lower than 700 N m (Fig. 10)",
    "R8": "polished: Φ̄ strongly lower, Ψ higher than ground (Fig. 11)",
    "R9": "sliding loss dominates at low speed; the rolling loss grows with speed to a significant share",
    "R10": "roll angle 17°, speed E: ground gives asperity pressures above 3 GPa; polished a full film "
    "with p well below 2 GPa (Fig. 12)",
    "R11": "roll angle 25°, speeds B and E: tribo-dynamic ph ≈ 0.8 GPa at both; temperature rise much "
    "higher at E (Fig. 7)",
}
PAPER_TRIBO_DYNAMIC_W = {"A": 257.0, "B": 343.0, "D": 431.0, "E": 948.0}
PAPER_QUASI_STATIC_W = {"A": 276.0, "B": 302.0, "D": 526.0, "E": 532.0}
PAPER_R3 = {"A": "lower", "B": "higher", "C": "nearly equal", "D": "lower", "E": "higher"}

#: Where points A-E sit when the sweep cannot locate the resonance peaks (REFERENCE §6: A just below
#: the 1750 rpm peak, B just above it, C away from both peaks, D just below 3500 rpm, E at it).
NOMINAL_POINTS_RPM = {"A": 1700.0, "B": 1800.0, "C": 2600.0, "D": 3400.0, "E": 3500.0}
#: Speeds of the quick run: the nominal points plus the ends of the paper's sweep.
QUICK_SPEEDS_RPM = (500.0, 1700.0, 1800.0, 2600.0, 3400.0, 3500.0, 4200.0)
#: |Φ̄_TD − Φ̄_QS| / Φ̄_QS below which tribo-dynamic and quasi-static count as "nearly equal" (R3).
NEARLY_EQUAL = 0.03
#: Roll angles of the paper's contact-field figures, degrees of gear 1.
FIELD_ROLL_ANGLE_DEG = {7: 25.0, 12: 17.0}
#: Fig. 12 (and R10) solve the contact with the roughness profiles themselves (deterministic mixed
#: EHL), as the paper does; the coupled model's statistical mixed rung gives the mean film only, with
#: no asperity pressures to show. The profiles are the runs' synthetic surfaces as a stylus
#: instrument measures them (``field_surfaces``): band-limited at λs = 2.5 µm, the ISO 3274 cutoff
#: for λc = 0.8 mm (the paper put measured profiles in its film). Unfiltered, the exponential
#: autocorrelation has no finest scale and the film moves with the grid (studies/roughness_resolution). Filtered, this contact settles by 2049 nodes (Δx ≈ 0.5 µm at 17°):
#: polished p_max and h_min within 0.5 % of 4097 nodes, ground p_max within 2 % of 1025 nodes
#: (studies/roughness_resolution, ``fig12_resolution``). The ground film's asperity load is what still moves (the > 3 GPa peaks
#: are micro-EHL pressure in a film 26 nm thin at its thinnest), as at the pitch contact, where
#: that film needs Δx ≲ λs/13 (studies/roughness_resolution). Steady and iso-thermal: the thermal
#: deterministic film's Poiseuille heat is not grid-converged (docs/limitations.md,
#: deterministic roughness); and the roughness is frozen at the instant (moving roughness:
#: ``solve_ehl_passage``).
FIELD_DETERMINISTIC_NODES = 2049
FIELD_SHORT_CUTOFF = 2.5e-6  # m, λs of ISO 3274 for λc = 0.8 mm (ground and polished flanks)

BASELINE_INLET_C, VARIANT_INLET_C = 90.0, 60.0
BASELINE_TORQUE, VARIANT_TORQUE = 700.0, 1500.0
