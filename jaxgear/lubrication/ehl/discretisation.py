"""The dimensionless problem: Hertz scales of a contact (``_scales``), the grids and their
discrete system F(u) = 0 (``_Level``: Reynolds with Fischer-Burmeister cavitation, the
deformation, the load row, the exact Jacobian), the grid sequence (``_levels``), Moes' film
estimate, and the roughness and the earlier films a transient step reads (``_film_at_feet``)."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array

from .. import asperity as asperity_mod
from .. import deformation as deformation_mod
from .. import rheology
from ..lubricant import Lubricant
from ..reynolds import (
    fischer_burmeister,
    reynolds_residual,
    smooth_positive,
)
from .model import EHLModel, LineContact, _Inputs, _Numbers, _split_numbers

_LOG_VISCOSITY_CAP = 500.0  # cap on ln(η/η0): keeps iterates finite (η/η0 ≤ e^500)
_FLOOR_FRACTION = 1e-3  # smooth film floor inside ε, relative to the reference film
# smoothing of the pressure limit's kink P = min(v, P_cap) (``EHLModel.hardness``), in ph
_PLASTIC_SMOOTHING = 1e-4
# plastic gap per unit of v above the limit, × the reference film H_ref (the unknowns' scaling)
_PLASTIC_GAP_SCALE = 1.0
_KRYLOV_BLOCK = 128  # nodes a block of the block-Jacobi preconditioner
# Gauss-Legendre points of the asperity pressure's F_{5/2} in the residual: 48 (to ~1e-7 of it)
# instead of 160 (to ~1e-11); the residual evaluates it at every node in every Newton iteration
# and its band derivatives, and at 257 nodes 160 points took most of a solve's time
_ASPERITY_POINTS = 48


def moes_central_film(m, l):
    """Moes' central film H_M = (hc/R)(2U)^(−1/2) for given M, L (line contact, Barus,
    incompressible).

    H_RI = 3/M, H_EI = 2.621 M^(−1/5), H_RP = 1.287 L^(2/3), H_EP = 1.311 M^(−1/8) L^(3/4),
    H_M = [(H_RI^(7/3) + H_EI^(7/3))^(3s/7) + (H_RP^(−7/2) + H_EP^(−7/2))^(−2s/7)]^(1/s) with
    s = (7 + 8 exp(−2 H_EI/H_RI))/5 (C.H. Venner & A.A. Lubrecht, Multilevel Methods in Lubrication,
    2000). Used here only as the starting estimate of the film.
    """
    h_ri = 3.0 / m
    h_ei = 2.621 * m ** (-0.2)
    h_rp = 1.287 * l ** (2.0 / 3.0)
    h_ep = 1.311 * m ** (-0.125) * l**0.75
    s = (7.0 + 8.0 * jnp.exp(-2.0 * h_ei / h_ri)) / 5.0
    a = (h_ri ** (7.0 / 3.0) + h_ei ** (7.0 / 3.0)) ** (3.0 * s / 7.0)
    b = (h_rp ** (-3.5) + h_ep ** (-3.5)) ** (-2.0 * s / 7.0)
    return (a + b) ** (1.0 / s)


class _Scales(eqx.Module):
    b: Array
    ph: Array
    um: Array
    us: Array
    eta0: Array
    log_eta0: Array
    rho0: Array
    log_lambda: Array
    log_kappa: Array  # ln(η0 |us| R/(τ0 b²)): Eyring parameter s = κ η̄/H
    squeeze: Array
    h_ref: Array
    x_in: Array
    x_out: Array
    moes_m: Array
    moes_l: Array


def _scales(model: EHLModel, inp: _Inputs) -> _Scales:
    c, lub = inp.contact, inp.lubricant
    r, w, e = c.reduced_radius, c.load_per_width, c.e_reduced
    b = c.hertz_half_width
    ph = c.hertz_pressure
    um = c.rolling_velocity
    us = c.sliding_velocity
    t_in = c.inlet_temperature
    log_eta0 = lub.log_base_viscosity(t_in)
    eta0 = jnp.exp(log_eta0)
    rho0 = lub.density_at(0.0, t_in, compressible=False)
    log_lambda = jnp.log(12.0 * eta0 * um * r**2 / (b**3 * ph))
    abs_us = jnp.sqrt(us * us + (1e-6 * um) ** 2)  # smooth |us| (gradient-safe at pure rolling)
    log_kappa = jnp.log(eta0 * abs_us * r / (lub.eyring_stress * b**2))
    alpha = lub.pressure_viscosity_coefficient(t_in)
    u_dim = eta0 * um / (e * r)
    w_dim = w / (e * r)
    m = w_dim * (2.0 * u_dim) ** -0.5
    l = alpha * e * (2.0 * u_dim) ** 0.25
    h_ref = moes_central_film(m, l) * jnp.pi / (8.0 * m)
    x_in, x_out = jnp.asarray(model.x_in), jnp.asarray(model.x_out)
    if model.auto_domain:
        x_in = jnp.minimum(x_in, -jnp.sqrt(50.0 * h_ref))
        x_out = jnp.maximum(x_out, 1.2 * jnp.sqrt(2.0 * h_ref))
    squeeze = b * inp.inv_time_step / um
    return _Scales(
        b,
        ph,
        um,
        us,
        eta0,
        log_eta0,
        rho0,
        log_lambda,
        log_kappa,
        squeeze,
        h_ref,
        x_in,
        x_out,
        m,
        l,
    )


def transport_shift(model: EHLModel, distance):
    """How far back along X a transient step reads its previous films, m: the distance the mean
    velocity carries the film in the step (∫ ur dt) along the characteristics
    (``EHLModel.transport = "characteristic"``), 0 for the Eulerian squeeze term."""
    return distance if model.transport == "characteristic" else jnp.zeros_like(distance)


def _extrapolated_interp(foot, x_previous, values):
    """Linear interpolation at ``foot``, held after the last node and extrapolated linearly
    before the first (the inlet, where a step along the characteristics reads upstream of the
    domain)."""
    inside = jnp.interp(foot, x_previous, values)
    slope = (values[1] - values[0]) / (x_previous[1] - x_previous[0])
    return jnp.where(foot < x_previous[0], values[0] + (foot - x_previous[0]) * slope, inside)


def _roughness_offset(mixed, surfaces, x, d):
    """The film offset −(S1 + S2) of a deterministic rough film, m, the surfaces displaced by
    ``d``; zero for the other films."""
    if mixed != "deterministic":
        return jnp.zeros_like(x)
    return -(surfaces.displaced_height(0, x, d[0]) + surfaces.displaced_height(1, x, d[1]))


def _film_at_feet(model, mixed, surfaces, x, shift, x_prev, rho_h, rho, d, radius):
    """ρh of an earlier step (on its nodes ``x_prev``, its surfaces displaced by ``d``) where this
    step's squeeze term reads it: at the nodes ``x`` (the Eulerian term), or along the
    characteristics (``EHLModel.transport``) at their feet x − ``shift``, with the roughness there
    evaluated from the profiles, not interpolated.

    Why the roughness apart: a step along the characteristics is exact for a film carried at the
    mean velocity only if it reads that film where it stood. Linear interpolation between nodes
    flattens a roughness a few cells long: on the polished film at the pitch contact (2049 nodes,
    BDF2) Courant numbers 0.5 and 0.25, whose feet fall between nodes, give a loss 20-22 % above
    the integer ones (as the grid that follows the Hertz width along the path would too); with the
    roughness evaluated, C = 0.5 is 1.3 % below C = 1.
    The rest of ρh (the smooth gap and the deformation) and the density are interpolated.

    Upstream of the earlier grid's first node (its grid narrower: the Hertz width grows with the
    load; or a foot upstream of the inlet) the rigid gap x²/(2R) (``radius`` R, this step's) and
    the roughness are taken out, the rest (h0, the deformation: slowly varying there) extrapolated
    linearly, and the gap and the roughness there put back at the first node's density (the
    inlet's pressure is ~0). Why: held at the first node's value, the earlier film would be read
    too thin by the gap's growth there, and the squeeze term would fill a gap that is not opening
    (where the load doubles in a step of a third of a Hertz width, the coupled transient rung's
    jumps, the inlet moves ~56 cells and that step's loss moves by 0.5 %). Inside the earlier grid
    ρh is interpolated as it is: in the Hertz zone the deformation cancels the rigid gap's
    curvature, so taking the gap out there would make the rest curved."""
    foot = x - shift if model.transport == "characteristic" else x
    offset_prev = _roughness_offset(mixed, surfaces, x_prev, d)
    rest_prev = rho_h - rho * offset_prev
    gap_prev = rho * x_prev**2 / (2.0 * radius)
    offset_foot = _roughness_offset(mixed, surfaces, foot, d)
    upstream = _extrapolated_interp(foot, x_prev, rest_prev - gap_prev) + rho[0] * (
        foot**2 / (2.0 * radius) + offset_foot
    )
    if model.transport != "characteristic":
        inside = jnp.interp(foot, x_prev, rho_h)
    else:
        rho_foot = _extrapolated_interp(foot, x_prev, rho)
        inside = jnp.interp(foot, x_prev, rest_prev) + rho_foot * offset_foot
    return jnp.where(foot < x_prev[0], upstream, inside)


def _grid(sc: _Scales, n: int):
    x = jnp.linspace(0.0, 1.0, n) * (sc.x_out - sc.x_in) + sc.x_in
    return x, (sc.x_out - sc.x_in) / (n - 1)


def _log_shear_factor(model: EHLModel, log_s, part: str = "flow"):
    """ln(η_s/η) of the shear model for ``part`` "flow" (the Reynolds flow coefficient, the
    Poiseuille heat, the damping) or "stress" (the sliding friction and heat): one law for both
    except "eyring_split" (``ehl_formula.split_laws``)."""
    from ..ehl_formula import split_laws
    from ..rheology import log_eyring_exact_factor, log_eyring_paper_factor

    stress_law, flow_law = split_laws(model.shear)
    law = flow_law if part == "flow" else stress_law
    if law == "eyring_paper":
        return log_eyring_paper_factor(log_s)
    if law == "eyring_exact":
        return log_eyring_exact_factor(log_s)
    return jnp.zeros_like(log_s)


class _Level(eqx.Module):
    """The discrete system on one grid: F(u) = 0, u = [P (n), H0]."""

    model: EHLModel = eqx.field(static=True)
    n: int = eqx.field(static=True)
    inp: _Inputs
    sc: _Scales
    x: Array
    spacing: Array
    # influence matrix rows i = −2 … n (n + 3, n): D[i, j] = d(i − j); None on Krylov levels
    # (``EHLModel.use_krylov``), which apply D by FFT and never assemble J
    kernel_rows: Array | None
    # d(m) for m = −(B + 2) … B + 2 (index m + B + 2), B = _KRYLOV_BLOCK: the Toeplitz kernel near
    # its diagonal (the relaxation's and the block preconditioner's)
    kernel_near: Array
    temperature: Array
    log_eta0_nodes: Array  # ln η0(T) at the nodes (ambient pressure), η in Pa s
    alpha_nodes: Array  # α(T) at the nodes, 1/Pa
    rho_nodes: Array  # ρ(0, T)/ρ0 at the nodes
    offset: Array  # dimensionless film offset
    rho_h_prev: Array  # dimensionless ρ̄H of the previous step
    # 1, or 0 in a transient step whose squeeze term is the material derivative along the
    # characteristics (``EHLModel.transport``), which carries the wedge term
    wedge_weight: Array

    def with_roughness(self, factor):
        """The same system with the film offset (roughness) scaled by ``factor``."""
        return eqx.tree_at(lambda lev: lev.offset, self, self.offset * factor)

    def smooth_steady(self):
        """The same system without roughness and without the squeeze term (so with the wedge)."""
        return eqx.tree_at(
            lambda lev: (lev.offset, lev.sc.squeeze, lev.wedge_weight),
            self,
            (
                jnp.zeros_like(self.offset),
                jnp.zeros_like(self.sc.squeeze),
                jnp.ones_like(self.wedge_weight),
            ),
        )

    def density(self, p):
        """ρ̄(P) at the nodes (dimensionless)."""
        if self.model.compressibility == "dowson_higginson":
            pressure = self.sc.ph * p
            return self.rho_nodes * rheology.dowson_higginson_density(pressure, 0.0, 1.0, 0.0, 0.0)
        return self.rho_nodes

    def rho_h(self, u):
        """ρ̄H at the nodes for the state u (what the squeeze term of the next step reads); H the
        film that carries the flow (``gap``)."""
        p, h = self.plastic(u[: self.n])[0], self.film(u)
        return self.density(self.fluid(p, h)) * self.gap(h)

    def _roughness(self):
        """The dimensionless composite roughness σ R/b² (floored: a statistical film of zero
        roughness is the smooth film)."""
        h_scale = self.sc.b**2 / self.inp.contact.reduced_radius
        return jnp.maximum(self.inp.roughness, 1e-12) / h_scale

    def asperity(self, h):
        """The dimensionless Greenwood-Tripp asperity pressure p_a/ph at the film H (the
        mean-plane separation) of a statistical film; zero for the others."""
        if not self.inp.mean_plane:
            return jnp.zeros_like(h)
        sigma = self._roughness()
        k = asperity_mod.asperity_constant(
            self.inp.numbers.asperity_density_product, self.inp.numbers.asperity_slope_ratio
        )
        e_over_ph = self.inp.contact.e_reduced / self.sc.ph
        return k * e_over_ph * asperity_mod.gt_integral(2.5, h / sigma, _ASPERITY_POINTS)

    def fluid(self, p, h):
        """The fluid's pressure P − p_a(H) (P the total pressure unknown)."""
        return p - self.asperity(h) if self.inp.mean_plane else p

    def gap(self, h):
        """The film that carries the flow: the average gap h_T(H) of a statistical film, H of the
        others."""
        if not self.inp.mean_plane:
            return h
        return asperity_mod.average_gap(h, self._roughness())

    def flow_factor(self, h):
        """Patir and Cheng's pressure flow factor φx(H) of a statistical film; 1 for the others."""
        if not self.inp.mean_plane:
            return jnp.ones_like(h)
        return asperity_mod.pressure_flow_factor(h, self._roughness())

    def plastic(self, v):
        """(P, δ) of the pressure unknowns v: the pressure and the dimensionless plastic gap.

        Without a pressure limit (``EHLModel.hardness`` None) P = v and δ is None. With one,
        P = min(v, P_cap) and δ = c H_ref max(v − P_cap, 0) (c = ``_PLASTIC_GAP_SCALE``, both
        smoothed over ``_PLASTIC_SMOOTHING``): where the surface yields, its pressure stays at the
        limit and the gap opens by δ ≥ 0 (the asperity flattened), complementary to P_cap − P ≥ 0.
        The Reynolds equation holds at every node, plastic ones included, so the flow is conserved
        there."""
        if self.model.hardness is None:
            return v, None
        cap = self.model.hardness / self.sc.ph
        excess = smooth_positive(v - cap, _PLASTIC_SMOOTHING)
        return v - excess, _PLASTIC_GAP_SCALE * self.sc.h_ref * excess

    def shape(self, v):
        """The film without H0 and the rigid gap: deformation, offset (roughness) and plastic gap
        for the pressure unknowns v."""
        p, delta = self.plastic(v)
        h = self.deformation(p) + self.offset
        return h if delta is None else h + delta

    def deformation(self, p):
        if self.model.use_fft(self.n):
            return deformation_mod.deformation_fft(p, self.spacing)
        # the whole padded matrix times p, then the rows wanted: slicing the matrix first would copy
        # it (XLA does not fuse a slice into a dot operand)
        return (self.kernel_rows @ p)[2 : self.n + 2]

    def film(self, u):
        p, delta = self.plastic(u[: self.n])
        h = u[self.n] + 0.5 * self.x**2 + self.offset + self.deformation(p)
        return h if delta is None else h + delta

    def local(self, p, h, s):
        """Node-wise FB residual as a function of P and H (banded dependence, bandwidth −2…+1):
        the complementarity of the fluid's pressure and the Reynolds residual."""
        r, diag = self.reynolds(p, h, s)
        pf = self.fluid(p, h)
        f = fischer_burmeister(pf, -r / (1.0 + diag), self.model.smoothing(self.inp.rough))
        return f.at[0].set(pf[0]).at[-1].set(pf[-1])

    def reynolds(self, p, h, s):
        """The discrete Reynolds residual R and its Poiseuille diagonal D (``reynolds_residual``) as
        functions of P and H (of a statistical film: the total pressure and the mean-plane
        separation; the flow then carries the fluid's pressure and the average gap)."""
        m, sc = self.model, self.sc
        factor = self.flow_factor(h)
        p, h = self.fluid(p, h), self.gap(h)
        pressure = sc.ph * p
        log_eta = self.log_eta0_nodes - sc.log_eta0
        if m.viscosity == "barus":
            log_eta = log_eta + rheology.barus_log_pressure_factor(pressure, self.alpha_nodes)
        else:
            log_eta = log_eta + rheology.roelands_log_pressure_factor(
                pressure, self.log_eta0_nodes, self.inp.lubricant.roelands_z
            )
        log_eta = s * log_eta
        log_eta = jnp.minimum(log_eta, _LOG_VISCOSITY_CAP)
        rho = self.density(p)
        h_eff = smooth_positive(h, _FLOOR_FRACTION * sc.h_ref)
        if m.shear == "newtonian":
            log_eta_s = log_eta
        else:
            log_s = sc.log_kappa + log_eta - jnp.log(h_eff)
            log_eta_s = log_eta + _log_shear_factor(m, log_s)
        log_eps = jnp.log(factor * rho * h_eff**3) - log_eta_s - sc.log_lambda
        return reynolds_residual(
            p,
            rho * h,
            log_eps,
            self.spacing,
            sc.squeeze,
            self.rho_h_prev,
            m.wedge_order,
            self.wedge_weight,
        )

    def load_row(self, p):
        return (self.spacing * jnp.sum(p) - 0.5 * jnp.pi) / (0.5 * jnp.pi)

    def residual(self, u, s=1.0):
        p = self.plastic(u[: self.n])[0]
        return jnp.concatenate([self.local(p, self.film(u), s), self.load_row(p)[None]])

    def bands(self, u, s):
        """The band derivatives of ``local`` at u (``_bands``) with respect to the unknowns v and
        to the elastic film (the film without the plastic gap), dP/dv (None without a pressure
        limit), and ``local`` itself at u: J = band(dv) + dh D diag(dP/dv)."""
        v = u[: self.n]
        if self.model.hardness is None:
            value, dvs, dhs = _bands(lambda pp, hh: self.local(pp, hh, s), v, self.film(u))
            return dvs, dhs, None, value
        elastic = self.film(u) - self.plastic(v)[1]

        def local_v(vv, hh):
            pp, dd = self.plastic(vv)
            return self.local(pp, hh + dd, s)

        value, dvs, dhs = _bands(local_v, v, elastic)
        slope = jax.jvp(lambda vv: self.plastic(vv)[0], (v,), (jnp.ones_like(v),))[1]
        return dvs, dhs, slope, value

    def jacobian(self, u, s=1.0):
        return self.residual_and_jacobian(u, s)[1]

    def residual_and_jacobian(self, u, s=1.0):
        """(``residual``, its Jacobian) at u, from one linearisation of the residual: Newton's
        iteration reads the residual at its iterate here instead of evaluating it again."""
        n = self.n
        p = u[:n]
        dps, dhs, slope, value = self.bands(u, s)
        residual = jnp.concatenate([value, self.load_row(self.plastic(p)[0])[None]])
        rows = jnp.arange(n)
        offsets = _BAND
        # J[i, j] = Σ_k dP_k[i] [j = i + k] + Σ_k dH_k[i] D[i + k, j]: the shifted influence rows
        # are slices of the level's padded matrix (built once per solve, outside the Newton loop),
        # so the assembly is one fused elementwise pass over n² entries, with no gathers
        # the barrier ties the influence rows to this Newton iterate: otherwise XLA hoists the four
        # n × n slices (and masks) out of the Newton while-loop as loop invariants, materialising
        # them before every solve even when it takes no iteration (~15 ms at N = 1025)
        kernel_rows = self.kernel_rows
        if kernel_rows is None:  # a Krylov level's J for the implicit derivative: built here
            kernel_rows = deformation_mod.influence_rows(n, self.spacing, before=2, after=1)
        kernel_rows, rows_b, _ = jax.lax.optimization_barrier((kernel_rows, rows, u))
        m = rows_b[:, None] - rows_b[None, :]
        dense = jnp.zeros((n, n), dtype=p.dtype)
        for k, dp, dh in zip(offsets, dps, dhs, strict=True):
            shifted = kernel_rows[k + 2 : k + 2 + n]
            if slope is not None:  # the deformation responds to P = P(v): its columns × dP/dv
                shifted = shifted * slope[None, :]
            dense = dense + dh[:, None] * shifted + jnp.where(m == -k, dp[:, None], 0.0)
        h0_col = sum(dhs)
        top = jnp.concatenate([dense, h0_col[:, None]], axis=1)
        load = jnp.full((n,), self.spacing / (0.5 * jnp.pi), dtype=p.dtype)
        if slope is not None:
            load = load * slope
        bottom = jnp.concatenate([load[None, :], jnp.zeros((1, 1))], axis=1)
        return residual, jnp.concatenate([top, bottom], axis=0)


_BAND = (-2, -1, 0, 1)  # node offsets k of the banded dependence of a node's residual on P, H


def _bands(fn, p, h):
    """fn(p, h) (node-wise, banded in ``_BAND``) and its band derivatives: lists over k of
    ∂fn_i/∂p_{i+k} and ∂fn_i/∂h_{i+k} (zero outside the grid), by four coloured
    directional derivatives each."""
    n = p.shape[0]
    value, lin = jax.linearize(fn, p, h)
    colour = jnp.arange(n)[None, :] % 4 == jnp.arange(4)[:, None]
    seeds = colour.astype(p.dtype)
    zero = jnp.zeros_like(seeds)
    jp = jax.vmap(lin)(seeds, zero)  # (4, n): row i, coloured column
    jh = jax.vmap(lin)(zero, seeds)
    rows = jnp.arange(n)
    dps, dhs = [], []
    for k in _BAND:
        col = rows + k
        valid = (col >= 0) & (col < n)
        dps.append(jnp.where(valid, jp[col % 4, rows], 0.0))
        dhs.append(jnp.where(valid, jh[col % 4, rows], 0.0))
    return value, dps, dhs


def _make_level(model: EHLModel, inp: _Inputs, sc: _Scales, n: int, fine_n: int) -> _Level:
    x, spacing = _grid(sc, n)
    near = deformation_mod.influence_vector(_KRYLOV_BLOCK + 3, spacing)
    kernel = (
        None
        if model.use_krylov(n)
        else deformation_mod.influence_rows(n, spacing, before=2, after=1)
    )
    r = inp.contact.reduced_radius
    h_scale = sc.b**2 / r
    if n == fine_n:
        offset = inp.film_offset / h_scale
        prev = inp.rho_h_previous / (sc.rho0 * h_scale)
        rise = inp.temperature_rise
    else:
        x_fine, _ = _grid(sc, fine_n)
        offset = jnp.interp(x, x_fine, inp.film_offset) / h_scale
        prev = jnp.interp(x, x_fine, inp.rho_h_previous) / (sc.rho0 * h_scale)
        rise = jnp.interp(x, x_fine, inp.temperature_rise)
    t = inp.contact.inlet_temperature + rise
    lub = inp.lubricant
    log_eta0 = lub.log_base_viscosity(t)
    alpha = rheology.roelands_pressure_viscosity_coefficient(log_eta0, lub.roelands_z)
    rho = lub.density_at(0.0, t, compressible=False) / sc.rho0
    # a transient step along the characteristics carries the wedge in its squeeze term
    characteristic = model.transport == "characteristic"
    wedge_weight = jnp.where(characteristic & (inp.inv_time_step > 0.0), 0.0, 1.0)
    return _Level(
        model,
        n,
        inp,
        sc,
        x,
        spacing,
        kernel,
        near,
        t,
        log_eta0,
        alpha,
        rho,
        offset,
        prev,
        wedge_weight,
    )


def _levels(model: EHLModel, inp: _Inputs):
    sc = _scales(model, inp)
    sizes = model.grid_sizes
    return sc, [_make_level(model, inp, sc, n, sizes[-1]) for n in sizes]


def _fine_level(model: EHLModel, inp: _Inputs):
    """Only the finest grid (no coarse influence matrices built)."""
    sc = _scales(model, inp)
    return sc, _make_level(model, inp, sc, model.n_nodes, model.n_nodes)


def _grid_positions(model: EHLModel, contact: LineContact, lubricant: Lubricant):
    """Node positions x (m) of ``solve_ehl``'s fine grid for this contact."""
    n = model.n_nodes
    z = jnp.zeros((n,))
    if model.boundary_friction is not None:  # a full model: its static part selects the grid
        _, model = _split_numbers(model)
    zero = jnp.zeros(())
    numbers = _Numbers(zero, zero, zero, zero)  # the grid does not depend on them
    inp = _Inputs(contact, lubricant, z, zero, z, z, zero, numbers)
    sc = _scales(model, inp)
    x, _ = _grid(sc, n)
    return x * sc.b


def hertz_film_scale(contact: LineContact):
    """b²/R, m: the film thickness unit of the Hertz scaling H = h R/b²."""
    return contact.hertz_half_width**2 / contact.reduced_radius
