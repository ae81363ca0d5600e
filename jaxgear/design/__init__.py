"""Design tools on top of ``simulate``: constrained and multi-objective tip relief optimisation,
Pareto fronts, sensitivity reports and calibration of model constants."""
