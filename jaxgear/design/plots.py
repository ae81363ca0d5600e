"""Figures of the design tools: a constrained optimisation's outcome and a Pareto front (PNG)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import _pyplot

# Display: (label unit, factor from SI) per quantity.
_SHOW = {
    "efficiency": ("%", 100.0),
    "power_loss": ("W", 1.0),
    "dte_rms": ("µm", 1e6),
    "hertz_pressure": ("GPa", 1e-9),
    "flash_temperature": ("K", 1.0),
}


def _show(name):
    return _SHOW.get(name, ("", 1.0))


def plot_design(result, path: str | Path) -> Path:
    """Each constrained (and the objective's) quantity per duty-cycle point at the start and the
    optimum, with its limit, and the path of the design variables (PNG)."""
    plt = _pyplot()
    names = list(result.values)
    fig, axes = plt.subplots(1, len(names) + 1, figsize=(4.2 * (len(names) + 1), 3.6))
    points = np.arange(result.speeds_rpm.size)
    ticks = [f"{s:.0f}\n{t:.0f}" for s, t in zip(result.speeds_rpm, result.torques)]
    for ax, name in zip(axes, names):
        unit, factor = _show(name)
        ax.plot(points, np.asarray(result.values_start[name]) * factor, "o--", label="start")
        ax.plot(points, np.asarray(result.values[name]) * factor, "s-", label="optimum")
        if name in result.limits:
            ax.axhline(result.limits[name] * factor, color="k", lw=0.8, ls=":", label="limit")
        ax.set_xticks(points, ticks, fontsize=7)
        ax.set(xlabel="rpm / N m", ylabel=f"{name} ({unit})" if unit else name, title=name)
        ax.legend(fontsize=7)
    path_x = np.asarray(result.path)
    ax = axes[-1]
    ax.plot(path_x[:, 0] * 1e6, np.degrees(path_x[:, -1 if len(result.names) == 2 else 2]), ".-")
    ax.plot(path_x[-1, 0] * 1e6, np.degrees(path_x[-1, -1 if len(result.names) == 2 else 2]),
            "r*", ms=12)  # fmt: skip
    ax.set(xlabel="relief amount (µm)", ylabel="relief start (deg)", title="Design path")
    for a in axes:
        a.grid(alpha=0.3)
    fig.suptitle(f"Tip relief: {result.message}", fontsize=9)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def plot_pareto(front, path: str | Path) -> Path:
    """The objective against the traded quantity; dominated or failed points hollow (PNG)."""
    plt = _pyplot()
    unit_t, f_t = _show(front.trade)
    objective = front.objective if front.objective in _SHOW else front.objective.split("_max")[0]
    unit_o, f_o = _show(objective)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    eff = front.efficient
    order = np.argsort(front.trade_values)
    ax.plot(front.trade_values[order][eff[order]] * f_t,
            front.objective_values[order][eff[order]] * f_o, "o-", label="front")  # fmt: skip
    if np.any(~eff):
        ax.plot(front.trade_values[~eff] * f_t, front.objective_values[~eff] * f_o, "o",
                mfc="none", label="dominated or not converged")  # fmt: skip
    ax.set(xlabel=f"largest {front.trade} over the duty cycle ({unit_t})",
           ylabel=f"{front.objective} ({unit_o})", title="Pareto front (ε-constraint)")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
