"""The paper's Figs. 3-12 drawn from a ``PaperReproduction``: ``figure`` draws one (a matplotlib
Figure), ``save_figures`` writes all of them.

What a figure shows depends on the fidelity: pressure and film profiles need an EHL friction rung,
temperatures the thermal rung, asperity pressures the mixed (rough-surface) rung, the iso-thermal
comparison a thermal run to compare with. A figure the fidelity cannot give is not drawn from
something else: ``figure`` raises ``FigureUnavailable`` with the reason, ``save_figures`` records it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import _pyplot as plt
from .reference import FIGURES
from .reproduce import FigureUnavailable, PaperReproduction, _mark

# --------------------------------------------------------------------------------------------------
# Figures


def figure(repro: PaperReproduction, number: int):
    """The paper's Fig. ``number`` (3-12) drawn from ``repro``: a matplotlib Figure.

    Raises:
        FigureUnavailable: the fidelity or the run cannot give what the figure shows (``.reason``).
        ValueError: ``number`` is not one of FIGURES.
    """
    if number not in FIGURES:
        raise ValueError(f"number = {number!r} is not valid; valid choices: {FIGURES}")
    return _DRAW[number](repro)


def _pyplot():

    return plt()


def _mark_points(ax, repro, values, scale=1.0):
    for name, i in repro.points.items():
        y = float(np.asarray(values)[i]) * scale
        if np.isfinite(y):
            ax.annotate(
                name,
                (repro.speeds[i], y),
                textcoords="offset points",
                xytext=(0, 6),
                ha="center",
                fontsize=8,
                color="C3",
            )
            ax.plot(repro.speeds[i], y, "o", ms=4, color="C3")


def _flag(ax, speeds, values, result, scale=1.0):
    """Mark the points of ``result`` that failed (x) and those reported as attractor means (o)."""
    marks = (
        (np.asarray(result.failed), "x", "not converged (kept, flagged)"),
        (np.asarray(result.on_attractor), "o", "no stable periodic orbit (attractor mean)"),
    )
    for mask, marker, label in marks:
        if mask.any():
            ax.plot(
                np.asarray(speeds)[mask],
                np.asarray(values)[mask] * scale,
                marker,
                mfc="none",
                color="k",
                ms=6,
                zorder=5,
                label=label if label not in ax.get_legend_handles_labels()[1] else None,
            )


def _finish(fig, ax_list, title):
    for ax in ax_list:
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def _subtitle(repro):
    fid = repro.fidelity
    thermal = "thermal" if fid.thermal else "iso-thermal"
    quick = ", quick run" if repro.quick else ""
    return (
        f"jaxgear, friction {fid.friction!r}, {thermal}, {fid.n_positions} positions/cycle"
        f"{_contact_parameters(fid)}{quick}"
    )


def _contact_parameters(fid):
    """The open contact parameters where they differ from the defaults (e.g. those of
    ``Fidelity.paper_calibrated()``), as ", shear 'eyring_split', nβσ 0.08"; else ""."""
    default = type(fid)()
    parts = []
    if fid.shear != default.shear:
        parts.append(f"shear {fid.shear!r}")
    if fid.asperity_density_product != default.asperity_density_product:
        parts.append(f"nβσ {float(fid.asperity_density_product):g}")
    if fid.asperity_slope_ratio != default.asperity_slope_ratio:
        parts.append(f"σ/β {float(fid.asperity_slope_ratio):g}")
    if fid.boundary_friction != default.boundary_friction:
        parts.append(f"μb {float(fid.boundary_friction):g}")
    return "".join(", " + p for p in parts)


def _fig3(repro):
    plt = _pyplot()
    td = repro.tribo_dynamic
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(repro.speeds, 1e6 * td.dte_rms, ".-", ms=3, label="tribo-dynamic")
    _mark_points(ax, repro, td.dte_rms, 1e6)
    _flag(ax, repro.speeds, td.dte_rms, td, 1e6)
    for rpm in (1750.0, 3500.0):
        ax.axvline(rpm, color="0.6", lw=0.8, ls=":", label="paper's peaks" if rpm < 2000 else None)
    ax.set(xlabel="gear 1 speed (rpm)", ylabel="(εd)rms (µm)")
    ax.legend(fontsize=8)
    return _finish(fig, [ax], f"Fig. 3: RMS dynamic transmission error\n{_subtitle(repro)}")


def _parts(result):
    return {
        "total": np.asarray(result.power_loss),
        "sliding": np.asarray(result.power_loss_sliding),
        "rolling": np.asarray(result.power_loss_rolling),
    }


def _fig4(repro):
    plt = _pyplot()
    td, qs = repro.tribo_dynamic, repro.quasi_static
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    for key, ls in (("total", "-"), ("sliding", "--"), ("rolling", ":")):
        a.plot(repro.speeds, _parts(td)[key], ls, color="C0", label=f"{key}, tribo-dynamic")
        a.plot(repro.speeds, _parts(qs)[key], ls, color="C1", label=f"{key}, quasi-static")
    _flag(a, repro.speeds, td.power_loss, td)
    _mark_points(a, repro, td.power_loss)
    if not repro.fidelity.models_rolling:
        a.text(
            0.02,
            0.97,
            f"rolling loss: not modelled by the {repro.fidelity.friction!r} rung",
            transform=a.transAxes,
            va="top",
            fontsize=8,
        )
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=7, ncol=2, loc="lower right")
    b.plot(repro.speeds, 100 * td.efficiency, "-", label="tribo-dynamic")
    b.plot(repro.speeds, 100 * qs.efficiency, "--", label="quasi-static")
    b.axhspan(99.6, 99.85, color="0.9", label="paper's band (R4)")
    _flag(b, repro.speeds, td.efficiency, td, 100)
    b.set(xlabel="gear 1 speed (rpm)", ylabel="Ψ (%)", title="(b) mesh efficiency")
    b.legend(fontsize=8)
    return _finish(fig, [a, b], f"Fig. 4: power loss and efficiency\n{_subtitle(repro)}")


def _fig5(repro):
    plt = _pyplot()
    roll = np.degrees(np.asarray(repro.mesh.roll_angle))
    fig, axes = plt.subplots(1, 5, figsize=(16, 3.6), sharey=True)
    for ax, (name, i) in zip(axes, repro.points.items()):
        td = repro.tribo_dynamic.power_loss_position[i]
        qs = repro.quasi_static.power_loss_position[i]
        ax.plot(roll, td, "-", label="tribo-dynamic")
        ax.plot(roll, qs, "--", label="quasi-static")
        flag = _mark(repro.tribo_dynamic, i, " (attractor mean)", " (not converged)")
        ax.set(
            title=f"{name}: {repro.speeds[i]:.0f} rpm{flag}",
            xlabel="roll angle of the entering pair (°)",
        )
    axes[0].set_ylabel("Φ(t) (W)")
    axes[0].legend(fontsize=8)
    how = "around the DTE peaks" if repro.points_source == "peaks" else "at nominal speeds"
    return _finish(
        fig,
        axes,
        f"Fig. 5: power loss over one mesh cycle at points A-E ({how})\n{_subtitle(repro)}",
    )


def _compare(repro, number, key, label_base, label_variant, what):
    if key not in repro.variants:
        raise FigureUnavailable(number, repro.unavailable.get(key, f"{key} was not run"))
    plt = _pyplot()
    base, var = repro.variants["baseline"], repro.variants[key]
    v = repro.variant_speeds
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    for res, color, label in ((base, "C0", label_base), (var, "C2", label_variant)):
        parts = _parts(res)
        a.plot(v, parts["total"], "-", color=color, label=f"total, {label}")
        a.plot(v, parts["sliding"], "--", color=color, label=f"sliding, {label}")
        a.plot(v, parts["rolling"], ":", color=color, label=f"rolling, {label}")
        _flag(a, v, res.power_loss, res)
        b.plot(v, 100 * res.efficiency, "-", color=color, label=label)
        _flag(b, v, res.efficiency, res, 100)
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=7, ncol=2)
    b.set(xlabel="gear 1 speed (rpm)", ylabel="Ψ (%)", title="(b) mesh efficiency")
    b.legend(fontsize=8)
    return _finish(fig, [a, b], f"Fig. {number}: {what}, tribo-dynamic\n{_subtitle(repro)}")


def _fig6(repro):
    if "isothermal" not in repro.variants:
        raise FigureUnavailable(6, repro.unavailable["isothermal"])
    plt = _pyplot()
    base, iso = repro.variants["baseline"], repro.variants["isothermal"]
    v = repro.variant_speeds
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    a.plot(v, iso.power_loss, "-", color="C3", label="iso-thermal")
    a.plot(v, base.power_loss, "-", color="C0", label="thermal")
    a.set(xlabel="gear 1 speed (rpm)", ylabel="Φ̄ (W)", title="(a) mesh power loss")
    a.legend(fontsize=8)
    gap = 100 * (np.asarray(iso.power_loss) - base.power_loss) / base.power_loss
    b.plot(v, gap, ".-")
    b.set(xlabel="gear 1 speed (rpm)", ylabel="(Φ̄_iso − Φ̄_thermal)/Φ̄_thermal (%)", title="(b) gap")
    return _finish(fig, [a, b], f"Fig. 6: iso-thermal against thermal\n{_subtitle(repro)}")


def _fields_figure(repro, number, keys, title):
    fields = [repro.fields.get(k) for k in keys]
    missing = [f for f in fields if f is None or f.solution is None]
    if missing:
        reason = next((f.reason for f in missing if f is not None and f.reason), "")
        if not reason:
            reason = "; ".join(repro.unavailable.get(k, "") for k in keys if k in repro.unavailable)
        raise FigureUnavailable(number, reason or "the contact fields were not computed")
    plt = _pyplot()
    thermal = all(f.thermal for f in fields)
    rows = 3 if thermal else 2
    fig, axes = plt.subplots(
        rows, len(fields), figsize=(5.5 * len(fields), 2.6 * rows), squeeze=False
    )
    for col, f in enumerate(fields):
        sol = f.solution
        b = float(sol.hertz_half_width)
        x = np.asarray(sol.x) / b
        axes[0, col].plot(x, np.asarray(sol.p) / 1e9)
        axes[0, col].set(
            ylabel="p (GPa)",
            title=f"{f.label}: {f.speed_rpm:.0f} rpm, {f.roll_angle_deg:.2f}°, "
            f"ph {f.hertz_pressure / 1e9:.2f} GPa",
        )
        h = np.asarray(sol.h) * 1e6
        axes[1, col].plot(x, h)
        # The inlet gap grows to tens of µm: scale to the film inside the contact.
        inside = np.abs(x) <= 1.0
        top = 3.0 * float(np.max(h[inside])) if inside.any() else float(np.max(h))
        # (deterministic roughness: h < 0 where asperities are in contact, Hu-Zhu)
        bottom = min(0.0, 1.1 * float(np.min(h[inside]))) if inside.any() else 0.0
        axes[1, col].set(ylabel="h (µm)", ylim=(bottom, top))
        if thermal:
            rise = np.asarray(sol.temperature) - float(repro.op.inlet_temperature)
            axes[2, col].plot(x, rise)
            axes[2, col].set(ylabel="film temperature rise (K)")
        axes[-1, col].set(xlabel="x / b (Hertz half-widths)")
        for ax in axes[:, col]:
            ax.set_xlim(-2.5, 1.5)
    note = "" if thermal else " (no temperatures: iso-thermal solve)"
    models = sorted({f.model for f in fields if f.model})
    how = "".join(f"\n{m}" for m in models)
    return _finish(fig, axes.flat, f"Fig. {number}: {title}{note}\n{_subtitle(repro)}{how}")


def _fig7(repro):
    return _fields_figure(
        repro, 7, ("fig7_B", "fig7_E"), "pressure, film and temperature at roll angle 25°"
    )


def _fig8(repro):
    return _compare(repro, 8, "inlet_60C", "90 °C", "60 °C", "inlet temperature 60 against 90 °C")


def _fig9(repro):
    raise FigureUnavailable(
        9, "REFERENCE §7 does not say what the paper's Fig. 9 shows, so there is nothing to match"
    )


def _fig10(repro):
    return _compare(repro, 10, "torque_1500", "700 N m", "1500 N m", "torque 1500 against 700 N m")


def _fig11(repro):
    return _compare(repro, 11, "polished", "ground", "polished", "polished against ground")


def _fig12(repro):
    if repro.fidelity.friction != "ehl_mixed":
        raise FigureUnavailable(
            12,
            f"asperity contact pressures need the mixed EHL rung (rough surfaces); the "
            f"{repro.fidelity.friction!r} rung would draw ground and polished alike",
        )
    return _fields_figure(
        repro,
        12,
        ("fig12_ground", "fig12_polished"),
        "pressure and film at roll angle 17°, speed E, ground against polished",
    )


_DRAW = {
    3: _fig3,
    4: _fig4,
    5: _fig5,
    6: _fig6,
    7: _fig7,
    8: _fig8,
    9: _fig9,
    10: _fig10,
    11: _fig11,
    12: _fig12,
}
FIGURE_FILES = {
    3: "fig03_dte_rms.png",
    4: "fig04_power_loss_efficiency.png",
    5: "fig05_mesh_cycle_loss.png",
    6: "fig06_isothermal_vs_thermal.png",
    7: "fig07_fields_25deg.png",
    8: "fig08_inlet_temperature.png",
    9: "fig09.png",
    10: "fig10_torque.png",
    11: "fig11_surfaces.png",
    12: "fig12_fields_17deg.png",
}


def save_figures(repro: PaperReproduction, out_dir: str | Path) -> tuple[dict, dict]:
    """Write every figure that ``repro`` can give as PNG into ``out_dir``.

    Returns:
        (written: figure number → path, skipped: figure number → reason).
    """
    plt = _pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written, skipped = {}, {}
    for n in FIGURES:
        try:
            fig = figure(repro, n)
        except FigureUnavailable as err:
            skipped[n] = err.reason
            continue
        path = out / FIGURE_FILES[n]
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written[n] = path
    return written, skipped
