"""Small numerical building blocks shared by the solvers: Anderson acceleration, an early-exit
GMRES, implicit adjoints that give NaN where their linear solve fails, and a vmap-aware lazy cond."""
