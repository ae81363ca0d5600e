"""Matplotlib figures of jaxgear results (Agg backend; files only, no screens)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def plot_mesh_cycle(mesh, path: str | Path) -> Path:
    """Load share, Hertz pressure, mesh stiffness and static TE against gear 1 roll angle (PNG).

    Both pair slots are unrolled onto one roll-angle axis, so the curves follow one tooth pair
    through its whole engagement (slot 0, then slot 1 one base pitch later).
    """
    plt = _pyplot()
    roll0 = np.degrees(np.asarray(mesh.roll_angle))
    pitch_deg = roll0[1] - roll0[0]
    span = pitch_deg * mesh.n_positions
    roll = np.concatenate([roll0, roll0 + span])
    inside = np.concatenate([np.asarray(mesh.in_contact[:, 0]), np.asarray(mesh.in_contact[:, 1])])
    share = np.concatenate([np.asarray(mesh.load_share[:, 0]), np.asarray(mesh.load_share[:, 1])])
    ph = np.concatenate(
        [np.asarray(mesh.hertz_pressure[:, 0]), np.asarray(mesh.hertz_pressure[:, 1])]
    )
    keep = inside > 0
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=False)
    axes[0, 0].plot(roll[keep], share[keep], ".-", ms=3)
    axes[0, 0].set(
        xlabel="gear 1 roll angle (deg)",
        ylabel="load share of one tooth pair",
        title="Quasi-static load sharing",
    )
    axes[0, 1].plot(roll[keep], ph[keep] / 1e9, ".-", ms=3)
    axes[0, 1].set(
        xlabel="gear 1 roll angle (deg)",
        ylabel="Hertz pressure (GPa)",
        title="Maximum Hertz pressure",
    )
    axes[1, 0].plot(roll0, np.asarray(mesh.mesh_stiffness) / 1e8, ".-", ms=3)
    axes[1, 0].set(
        xlabel="roll angle of the entering pair (deg)",
        ylabel="km (1e8 N/m)",
        title="Mesh stiffness over one mesh cycle",
    )
    axes[1, 1].plot(roll0, np.asarray(mesh.static_te) * 1e6, ".-", ms=3, label="loaded static TE")
    axes[1, 1].plot(roll0, np.asarray(mesh.te_excitation) * 1e6, "--", label="TE excitation e(t)")
    axes[1, 1].set(
        xlabel="roll angle of the entering pair (deg)",
        ylabel="µm",
        title="Static transmission error",
    )
    axes[1, 1].legend()
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Mesh cycle at T1 = {float(mesh.torque):.0f} N m")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _paper_points(ax, ymax=None):
    """Mark the paper's resonance speeds (1750 and 3500 rpm, REFERENCE §7 R1)."""
    for rpm in (1750.0, 3500.0):
        ax.axvline(rpm, color="0.7", lw=0.8, ls=":")


def _mark_flagged(ax, speeds_rpm, values, ok, attractor=None):
    """Points whose solution did not converge as red crosses; ``attractor`` (a mask): points
    without a stable periodic orbit, whose values are means over the attractor, as open circles."""
    speeds, values = np.asarray(speeds_rpm), np.asarray(values)
    if attractor is not None and np.asarray(attractor, dtype=bool).any():
        on = np.asarray(attractor, dtype=bool)
        ax.plot(
            speeds[on],
            values[on],
            "o",
            mfc="none",
            color="C2",
            ms=5,
            label="no stable periodic orbit (attractor mean)",
        )
    if ok is None:
        return
    bad = ~np.asarray(ok, dtype=bool)
    if bad.any():
        ax.plot(speeds[bad], values[bad], "x", color="C3", ms=5, label="not converged (flagged)")


def plot_dte_rms(
    speeds_rpm, dte_rms, path, *, label="tribo-dynamic", others=(), ok=None, attractor=None
):
    """RMS dynamic transmission error (first 10 mesh harmonics) against speed, like the paper's Fig. 3.
    ``ok``: per-speed flags, False where a point failed (marked); ``attractor``: points whose values
    are means over an attractor (no stable periodic orbit), marked apart."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(speeds_rpm, np.asarray(dte_rms) * 1e6, ".-", ms=3, label=label)
    _mark_flagged(ax, speeds_rpm, np.asarray(dte_rms) * 1e6, ok, attractor)
    for other_label, values in others:
        ax.plot(speeds_rpm, np.asarray(values) * 1e6, "--", label=other_label)
    _paper_points(ax)
    ax.set(xlabel="gear 1 speed (rpm)", ylabel="(εd)rms (µm)", title="Dynamic transmission error")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_power_loss(speeds_rpm, dynamic, quasi_static, path, ok=None, labels=None, attractor=None):
    """Cycle-mean power loss against speed: sliding, rolling and total, tribo-dynamic against
    quasi-static (like the paper's Fig. 4a). ``dynamic``/``quasi_static``: dicts with keys
    "total", "sliding", "rolling" (W); ``quasi_static`` may be None (one model only). ``labels``:
    names of the two models (default "tribo-dynamic", "quasi-static")."""
    plt = _pyplot()
    first, second = labels or ("tribo-dynamic", "quasi-static")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    styles = {"total": "-", "sliding": "--", "rolling": ":"}
    for key, ls in styles.items():
        ax.plot(speeds_rpm, dynamic[key], ls, color="C0", label=f"{key}, {first}")
        if quasi_static is not None:
            ax.plot(speeds_rpm, quasi_static[key], ls, color="C1", label=f"{key}, {second}")
    _mark_flagged(ax, speeds_rpm, dynamic["total"], ok, attractor)
    _paper_points(ax)
    ax.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="Mesh power loss")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_efficiency(speeds_rpm, dynamic, quasi_static, path, ok=None, labels=None, attractor=None):
    """Mesh efficiency Ψ (%) against speed, tribo-dynamic against quasi-static (paper's Fig. 4b);
    ``quasi_static`` may be None. ``labels``: names of the two models."""
    plt = _pyplot()
    first, second = labels or ("tribo-dynamic", "quasi-static")
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(speeds_rpm, 100 * np.asarray(dynamic), "-", label=first)
    if quasi_static is not None:
        ax.plot(speeds_rpm, 100 * np.asarray(quasi_static), "--", label=second)
    _mark_flagged(ax, speeds_rpm, 100 * np.asarray(dynamic), ok, attractor)
    _paper_points(ax)
    ax.set(xlabel="gear 1 speed (rpm)", ylabel="Ψ (%)", title="Mesh efficiency")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_optimisation_history(result, path: str | Path, scales=None, labels=None) -> Path:
    """Objective, parameters and projected gradient norm against optimiser step (PNG).

    ``scales``/``labels``: per parameter, a factor and an axis label for display (default SI).
    """
    plt = _pyplot()
    n = len(result.names)
    scales = np.ones(n) if scales is None else np.asarray(scales, dtype=float)
    labels = list(result.names) if labels is None else list(labels)
    steps = np.arange(len(result.history_objective))
    fig, axes = plt.subplots(1, 2 + n, figsize=(4.2 * (2 + n), 3.6))
    axes[0].plot(steps, 100.0 * np.asarray(result.history_objective), ".-")
    axes[0].axhline(100.0 * result.objective, color="k", lw=0.8, ls="--", label="optimum")
    axes[0].set(xlabel="step", ylabel="mean efficiency (%)", title="Objective")
    axes[0].legend()
    for i in range(n):
        ax = axes[1 + i]
        ax.plot(steps, np.asarray(result.history_x)[:, i] * scales[i], ".-")
        for bound in (result.lower[i], result.upper[i]):
            ax.axhline(bound * scales[i], color="grey", lw=0.8, ls=":")
        ax.set(xlabel="step", ylabel=labels[i], title=labels[i])
    gn = np.asarray(result.history_gradient_norm)
    axes[-1].semilogy(steps, np.where(gn > 0, gn, np.nan), ".-")
    axes[-1].set(xlabel="step", ylabel="projected gradient norm", title="Stationarity")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Optimisation: {result.message}", fontsize=9)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
