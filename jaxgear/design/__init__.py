"""Design tools on top of ``simulate``: constrained and multi-objective tip relief optimisation
(``optimise_tip_relief``), Pareto fronts (``pareto_front``), sensitivity reports and calibration of
model constants. The named design quantities are in ``metrics``."""
