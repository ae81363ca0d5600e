"""The 6-DOF spur gear dynamic model of paper Eq. (1) as a diffrax vector field.

Degrees of freedom (per gear j = 1, 2): rotation θj, line-of-action (LOA) translation yj, off-line-of-action
(OLOA) translation xj. The gears turn at the nominal speeds Ωj (Ω2 = Ω1 z1/z2) and the model works with
the deviations φj = θj − Ωj t. Because r1Ω1 = r2Ω2 the nominal rotation adds nothing to the mesh
deflection, and the torsional dampers ct act on the deviation speeds φj' (a damper on the absolute speed
would be a constant drag of ct·Ω ≈ 3.7 kN m at 3500 rpm, far beyond the transmitted torque).

Equations (paper Eq. 1; Fm = km(t)·δ(d) the mesh force, F1, F2 the total friction forces per pair; the
back flanks' force, below, adds to them along the other line of action):

    J1 φ1'' + ct1 φ1' + r1 Fm = T1 + Σn F1n R1n
    m1 y1'' + cy1 y1' + ky1 y1 + Fm = 0
    m1 x1'' + cx1 x1' + kx1 x1 = −Σn F1n
    J2 φ2'' + ct2 φ2' − r2 Fm = −T2 − Σn F2n R2n
    m2 y2'' + cy2 y2' + ky2 y2 − Fm = 0
    m2 x2'' + cx2 x2' + kx2 x2 = +Σn F2n

with d = r1φ1 + y1 − r2φ2 − y2 − e(t) the mesh deflection relative to the excitation e(t) (the MeshCycle's
``te_excitation``; paper Eq. 1's εs). Signs: F1 is the friction force on gear 1 along its surface velocity
u1 = R1θ1' − x1' and −F2 the force on gear 2 along u2 = R2θ2' − x2' (paper Eqs. 3, 14-15). The paper
prints +ΣF1 / −ΣF2 on the x equations, which with its own Eq. 3 would make friction do work of the wrong
sign on xj; here the x equations carry the signs for which the friction power is exactly F1u1 − F2u2
(shown by the energy-balance test). Equivalently, x is positive against the surface motion.

The EHL mesh damping cm per pair acts along the OLOA direction (the common tangent, the direction of
sliding), not along the LOA: it adds f_dn = −cmn·v_sn to both F1n and F2n (paper Eq. 14-15), where
v_sn = (R1n φ1' − x1') − (R2n φ2' − x2') is the vibratory part of the sliding velocity. The nominal part
cm·us is the viscous sliding friction Fs itself, which the EHL already puts in the friction tables.

Load torque: T2 = T1 (r2/r1)(1 + s) with s solved together with the periodic orbit so that the mean speed
of both gears is exactly nominal (mean moment balance including the friction moments and damping): the
rigid-body rotation, free in Eq. 1, neither drifts nor needs an arbitrary spring.

Backlash (clearance 2ℓ along the LOA): the rotation origin is the drive-flank touching position, so the
drive flanks are compressed by d = εd − e(τ) where d > 0 (εd = r1φ1 + y1 − r2φ2 − y2; in static
equilibrium εd equals the loaded static TE). The back flanks touch on the other line of action LOA2,
the mirror image of LOA1 in the line of centres, at 2α_w to it (α_w the working pressure angle), and
are compressed by

    d_b = −[(r1φ1 − r2φ2) + cos 2α_w (y1 − y2) − sin 2α_w (x1 − x2)] − 2ℓ − e_b(τ)

where d_b > 0; the teeth are apart where neither compression is positive. The flank forces are
f_d = km(τ)⟨d⟩ ≥ 0 along LOA1 and f_b = −km_b(τ)⟨d_b⟩ ≤ 0 along LOA2 (⟨·⟩ the positive part), and
Fm = f_d + f_b is the mesh force of Eq. 1's rotation equations (both lines of action sit at rb
from the centres). In the translation equations Fm is replaced by f_d + cos 2α_w f_b along y, and
the x equations get +sin 2α_w f_b (gear 1) and −sin 2α_w f_b (gear 2): each force is −∂V/∂q of
V = ½km⟨d⟩² + ½km_b⟨d_b⟩². (With the module's axes: e_y along LOA1 from the driver towards the
driven gear, e_x against the surfaces' tangential motion at the drive contact, the force on gear 1
is f_b (−cos 2α_w e_y + sin 2α_w e_x) = f_b e_2, e_2 the unit vector along LOA2 whose force has
the driving moment; tests/gear/test_back_flanks.py builds both in the plane of the gears.)

The back contacts at phase τ are the drive contacts at phase frac(c − τ)
(``gear.mesh.back_flank_phase``), so ``back_flank="mirrored"`` (the default) gives the back flanks
the drive tables there: km_b(τ) = km(c − τ) and e_b(τ) = e(c − τ), the tip relief opening the
clearance on the back flanks as on the drive flanks. ``back_flank="same"`` is the usual single
backlash function δ(d + ℓ) of the drive side's km(τ) along LOA1 (δ(x) = x − ℓ above ℓ, 0 inside ±ℓ,
x + ℓ below −ℓ): km_b(τ) = km(τ), e_b(τ) = −e(τ) and 2α_w → 0. ``backlash="smooth"`` replaces the
kinks by softplus corners of width w.

Mesh damping along the line of action (``GearPair.mesh_damping_ratio`` ζ; 0, the paper's model, by
default): a viscous damper c = 2ζ √(k̄m me) in parallel with each flank pair's spring, on its
compression rate (d' = ε' − e'(t), d_b' likewise), acting only while the flanks touch: f_d =
km d + c d' where d > 0 (the back flanks' alike; a Kelvin-Voigt contact, whose damper may pull
while the flanks separate: see ``_contact_force``). It is the
usual linear mesh damping of gear-dynamics models (the squeeze and shear of the film and the
teeth's material damping lumped), which the paper leaves out; it cushions the impacts of rattling
teeth. ``backlash="smooth"`` weights the damper by the smoothed contact indicator σ(d/w).

Tables (km, e and the mesh-interface sums) are interpolated in time by periodic cubic splines (C²), so the
right-hand side is smooth between the M table points. The spline interpolates the data as given: a jump
in the data (a tooth pair entering with load) is reproduced with the usual local spline overshoot.
"""

from __future__ import annotations

from typing import Literal

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import check_finite, check_integer, check_non_negative, check_positive
from ..gear.geometry import gear_geometry
from ..gear.mesh import back_flank_phase

BacklashKind = Literal["exact", "smooth"]
BACKLASH_KINDS = ("exact", "smooth")
BACK_FLANK_KINDS = ("mirrored", "same")

#: Length scale of the dimensionless state (positions in µm).
LENGTH_SCALE = 1e-6


class MeshInterface(eqx.Module):
    """The lubricated mesh interface seen by the dynamics, per mesh position and tooth-pair slot.

    Tables over the same M positions (and pair slots) as the ``MeshCycle``; zero by default (dry,
    frictionless, undamped mesh). The tribo-dynamic model updates them from the EHL solutions.

    Attributes:
        damping: EHL mesh damping cm per pair, N s/m, shape [M, 2], ≥ 0 (paper Eq. 13).
        friction_1: friction force F1 on gear 1 per pair, N, [M, 2] (paper Eq. 14, without the cm term,
            which the dynamics adds from the vibratory sliding velocity): positive along gear 1's surface
            velocity.
        friction_2: F2 per pair, N, [M, 2] (paper Eq. 15, without the cm term): gear 2 receives −F2 along
            its surface velocity.
    """

    damping: Float[Array, "M 2"] = eqx.field(converter=jnp.asarray)
    friction_1: Float[Array, "M 2"] = eqx.field(converter=jnp.asarray)
    friction_2: Float[Array, "M 2"] = eqx.field(converter=jnp.asarray)

    def __check_init__(self):
        for name in ("damping", "friction_1", "friction_2"):
            shape = getattr(self, name).shape
            if len(shape) != 2 or shape[1] != 2:
                raise ValueError(
                    f"MeshInterface.{name} has shape {shape}; valid: shape [M, 2] (positions, pairs)"
                )
        if not self.damping.shape == self.friction_1.shape == self.friction_2.shape:
            raise ValueError("MeshInterface tables must share one shape [M, 2]")
        check_non_negative("MeshInterface.damping", self.damping, "N s/m")
        check_finite("MeshInterface.friction_1", self.friction_1)
        check_finite("MeshInterface.friction_2", self.friction_2)

    @classmethod
    def zeros(cls, n_positions: int) -> MeshInterface:
        """A dry, frictionless, undamped interface over ``n_positions`` mesh positions."""
        z = jnp.zeros((n_positions, 2))
        return cls(damping=z, friction_1=z, friction_2=z)

    @property
    def n_positions(self) -> int:
        return self.damping.shape[0]


class DynamicsOptions(eqx.Module):
    """Numerical choices of the dynamic model (static ones fix shapes and control flow).

    Attributes:
        backlash: "exact" (piecewise linear) or "smooth" (softplus corners; use it for gradients through
            contact loss). Static.
        backlash_width: corner width w of the smooth backlash, m (default 0.1 µm, 0.3 % of the static
            mesh deflection of the paper's pair at 700 N m).
        back_flank: the back flanks' stiffness, excitation and line of action where rattling teeth
            strike them (module docstring): "mirrored" (default; the drive tables at the mirrored
            phase, where the back contacts stand, and the force along the back flanks' own line of
            action) or "same" (the drive side's km(τ) and relative deflection at the same instant,
            along the drive line of action: the usual single backlash function). Static.
        steps_per_period: least number of fixed Runge-Kutta steps per mesh period. Static. The
            default 128 Tsit5 steps keep the DTE RMS of the paper's pair within ~1e-5 relative of a
            1024-step solve over 500-4200 rpm (benchmarks/dynamics.py prints the check).
        steps_per_mode_period: least number of steps per period of the highest natural frequency
            (at the largest mesh stiffness), so that low speeds, where one mesh period spans many
            vibration periods, stay accurate and stable (traced; the step count is then
            max(steps_per_period, steps_per_mode_period · f_max · Tm)).
        max_steps_per_period: upper bound of that count (static); beyond it (speeds below ~2 rpm
            for the paper's pair) the result is reported as not finite (status 2), never silently.
        newton_max_steps: Newton iterations on the periodicity condition for one speed. Static.
        newton_batch_steps: iterations for a whole batch of speeds together; members not converged
            by then are redone one at a time (transient decay, then ``newton_max_steps``). Static.
        newton_tol: convergence tolerance on the scaled periodicity residual (dimensionless, relative to
            the state's magnitude).
        solver: a diffrax Runge-Kutta solver (static structure), default Tsit5.
        transient_periods: mesh periods integrated to let transients decay before a second Newton
            attempt when the first fails or finds an unstable orbit. Static.
        n_positions: positions M of the mesh cycle built when none is passed. Static.
    """

    backlash: str = eqx.field(static=True, default="exact")
    backlash_width: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=1e-7)
    back_flank: str = eqx.field(static=True, default="mirrored")
    steps_per_period: int = eqx.field(static=True, default=128)
    steps_per_mode_period: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=16.0)
    max_steps_per_period: int = eqx.field(static=True, default=65536)
    newton_max_steps: int = eqx.field(static=True, default=30)
    newton_batch_steps: int = eqx.field(static=True, default=8)
    newton_tol: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=1e-9)
    solver: object = eqx.field(static=True, default=None)
    transient_periods: int = eqx.field(static=True, default=40)
    n_positions: int = eqx.field(static=True, default=64)

    def __check_init__(self):
        if self.backlash not in BACKLASH_KINDS:
            raise ValueError(
                f"DynamicsOptions.backlash = {self.backlash!r} is not valid; valid choices: "
                + ", ".join(map(repr, BACKLASH_KINDS))
            )
        if self.back_flank not in BACK_FLANK_KINDS:
            raise ValueError(
                f"DynamicsOptions.back_flank = {self.back_flank!r} is not valid; valid choices: "
                + ", ".join(map(repr, BACK_FLANK_KINDS))
            )
        check_positive("DynamicsOptions.backlash_width", self.backlash_width, "m")
        check_positive("DynamicsOptions.newton_tol", self.newton_tol)
        check_positive("DynamicsOptions.steps_per_mode_period", self.steps_per_mode_period)
        # Static counts: a float or NaN here would retrace per value or fail inside int().
        check_integer("DynamicsOptions.steps_per_period", self.steps_per_period, 8)
        check_integer(
            "DynamicsOptions.max_steps_per_period",
            self.max_steps_per_period,
            max(8, self.steps_per_period) if isinstance(self.steps_per_period, int) else 8,
        )
        check_integer("DynamicsOptions.newton_max_steps", self.newton_max_steps, 1)
        check_integer("DynamicsOptions.newton_batch_steps", self.newton_batch_steps, 1)
        check_integer("DynamicsOptions.transient_periods", self.transient_periods, 0)
        check_integer("DynamicsOptions.n_positions", self.n_positions, 4)


def backlash_exact(x, half_clearance):
    """Piecewise backlash δ(x): x − ℓ above ℓ, 0 inside ±ℓ, x + ℓ below −ℓ (m)."""
    return jnp.where(x > half_clearance, x - half_clearance, 0.0) + jnp.where(
        x < -half_clearance, x + half_clearance, 0.0
    )


def backlash_smooth(x, half_clearance, width):
    """Softplus backlash: w·[softplus((x − ℓ)/w) − softplus((−x − ℓ)/w)] (m); → exact as w → 0.

    Differs from the exact δ by at most w·ln 2 (at the corners) and by w·exp(−|x ∓ ℓ|/w) away from them.
    """
    return width * (
        jax.nn.softplus((x - half_clearance) / width)
        - jax.nn.softplus((-x - half_clearance) / width)
    )


def backlash_potential_exact(x, half_clearance):
    """P(x) with P' = δ (exact backlash): ½δ(x)², m²."""
    return 0.5 * backlash_exact(x, half_clearance) ** 2


class PeriodicSpline(eqx.Module):
    """Periodic cubic spline (C²) through samples y_i at τ_i = i/M of the unit period, several channels.

    The second derivatives solve the circulant system M_{i−1} + 4M_i + M_{i+1} = 6(y_{i+1} − 2y_i +
    y_{i−1})/h², diagonalised by the FFT.
    """

    values: Float[Array, "M C"]
    second: Float[Array, "M C"]

    def __init__(self, values):
        values = jnp.asarray(values)
        m = values.shape[0]
        k = jnp.arange(m)
        c = jnp.cos(2.0 * jnp.pi * k / m)
        gain = 6.0 * m**2 * (2.0 * c - 2.0) / (4.0 + 2.0 * c)
        spectrum = jnp.fft.fft(values, axis=0) * gain[:, None]
        self.values = values
        self.second = jnp.real(jnp.fft.ifft(spectrum, axis=0))

    def __call__(self, tau):
        m = self.values.shape[0]
        u = (tau - jnp.floor(tau)) * m
        i = jnp.clip(jnp.floor(u).astype(jnp.int32), 0, m - 1)
        s = (u - i)[..., None]  # τ of any shape: channels last
        j = (i + 1) % m
        h2 = 1.0 / m**2
        a = 1.0 - s
        return (
            a * self.values[i]
            + s * self.values[j]
            + h2 / 6.0 * ((a**3 - a) * self.second[i] + (s**3 - s) * self.second[j])
        )

    def slope(self, tau, channel: int):
        """d/dτ of channel ``channel`` at τ (any shape): the spline's exact derivative."""
        m = self.values.shape[0]
        u = (tau - jnp.floor(tau)) * m
        i = jnp.clip(jnp.floor(u).astype(jnp.int32), 0, m - 1)
        s = u - i
        j = (i + 1) % m
        y, second = self.values[:, channel], self.second[:, channel]
        h2 = 1.0 / m**2
        a = 1.0 - s
        return m * (
            y[j]
            - y[i]
            + h2 / 6.0 * ((1.0 - 3.0 * a**2) * second[i] + (3.0 * s**2 - 1.0) * second[j])
        )


# Channels of the interpolated table.
_KM, _E, _F1, _F1R, _F2, _F2R, _C0, _C1, _C2, _C11, _C12, _C22 = range(12)


def interface_channels(mesh, interface: MeshInterface) -> Float[Array, "M 12"]:
    """km, e and the per-pair sums of the interface the equations of motion need, per position."""
    r1 = mesh.radius_of_curvature[:, :, 0]
    r2 = mesh.radius_of_curvature[:, :, 1]
    cm = interface.damping
    f1 = interface.friction_1
    f2 = interface.friction_2
    cols = [
        mesh.mesh_stiffness,
        mesh.te_excitation,
        f1.sum(1),
        (f1 * r1).sum(1),
        f2.sum(1),
        (f2 * r2).sum(1),
        cm.sum(1),
        (cm * r1).sum(1),
        (cm * r2).sum(1),
        (cm * r1 * r1).sum(1),
        (cm * r1 * r2).sum(1),
        (cm * r2 * r2).sum(1),
    ]
    return jnp.stack(cols, axis=1)


class GearDynamics(eqx.Module):
    """Parameters of Eq. (1) at one operating point; ``__call__(τ, z, s)`` is the diffrax vector field.

    Time is the mesh-cycle fraction τ = t/Tm; the state is z = [q/L, (dq/dτ)/L] with
    q = [r1φ1, y1, x1, r2φ2, y2, x2] (m) and L = 1 µm; s is the load-torque correction (T2 = T1 r2/r1 (1+s)).
    """

    base_radius: Float[Array, "2"]
    inertia: Float[Array, "2"]
    mass: Float[Array, "2"]
    ky: Float[Array, "2"]
    cy: Float[Array, "2"]
    kx: Float[Array, "2"]
    cx: Float[Array, "2"]
    ct: Float[Array, "2"]
    half_clearance: Float[Array, ""]
    torque: Float[Array, ""]
    mesh_period: Float[Array, ""]
    step: Float[Array, ""]
    omega: Float[Array, "2"]
    tables: PeriodicSpline
    back_tables: PeriodicSpline
    back_phase: Float[Array, ""]
    back_angle: Float[Array, ""]
    backlash_width: Float[Array, ""]
    mesh_damping: Float[Array, ""]
    backlash: str = eqx.field(static=True)
    back_flank: str = eqx.field(static=True)

    @property
    def equivalent_mass(self) -> Float[Array, "2"]:
        """J/r², kg: the rotations' inertia seen along the LOA."""
        return self.inertia / self.base_radius**2

    def _positive(self, x):
        """⟨x⟩ of the chosen backlash model: max(x, 0), or w·softplus(x/w) (m)."""
        if self.backlash == "exact":
            return jnp.maximum(x, 0.0)
        return self.backlash_width * jax.nn.softplus(x / self.backlash_width)

    def back_direction(self):
        """(cos 2α_w, sin 2α_w): the back flanks' line of action (LOA2) in the (y, x) axes (module
        docstring); (1, 0) for ``back_flank="same"``, along the drive line of action."""
        return jnp.cos(self.back_angle), jnp.sin(self.back_angle)

    def back_deflection(self, q):
        """(r1φ1 − r2φ2) + c (y1 − y2) − s (x1 − x2) (m), (c, s) = ``back_direction``: the
        relative displacement along LOA2 that closes the back flanks' clearance when negative."""
        c, s = self.back_direction()
        return q[..., 0] - q[..., 3] + c * (q[..., 1] - q[..., 4]) - s * (q[..., 2] - q[..., 5])

    def _flanks(self, tau, q, tab=None):
        """(km, d, km_b, d_b) at time fraction τ for the displacements ``q`` [..., 6] (m): the
        drive and back flanks' stiffness (N/m) and compression (m; each flank pair touches where
        its compression is positive). ``tab``: the tables at τ, if already evaluated."""
        tab = self.tables(tau) if tab is None else tab
        km, e = tab[..., _KM], tab[..., _E]
        if self.back_flank == "same":
            km_b, e_b = km, -e
        else:
            back = self.back_tables(self.back_phase - tau)
            km_b, e_b = back[..., 0], back[..., 1]
        d = self.mesh_deflection(q, e)
        d_b = -self.back_deflection(q) - 2.0 * self.half_clearance - e_b
        return km, d, km_b, d_b

    def flank_compressions(self, tau, q):
        """(d, d_b): the drive and back flanks' compressions (m) at τ for the displacements ``q``
        [..., 6] (m); each flank pair touches where its compression is positive."""
        _, d, _, d_b = self._flanks(tau, q)
        return d, d_b

    def flank_rates(self, tau, v):
        """(dd/dt, dd_b/dt) (m/s): the drive and back flanks' rates of compression at τ for the
        velocities ``v`` [..., 6] (m/s), the excitations' rates included."""
        c, s = self.back_direction()
        de = self.tables.slope(tau, _E) / self.mesh_period
        if self.back_flank == "same":
            de_b = -de
        else:
            de_b = -self.back_tables.slope(self.back_phase - tau, 1) / self.mesh_period
        rate = v[..., 0] + v[..., 1] - v[..., 3] - v[..., 4] - de
        rel = v[..., 0] - v[..., 3] + c * (v[..., 1] - v[..., 4]) - s * (v[..., 2] - v[..., 5])
        return rate, -rel - de_b

    def _contact_force(self, k, d, rate):
        """One flank pair's normal force (N): k⟨d⟩, plus the mesh damper c·rate while the flanks
        touch (d > 0; under the smooth backlash weighted by the smoothed contact indicator
        σ(d/w)). Nothing acts while they are apart; while they touch the damper pushes them
        apart as they close and may pull as they separate, as in a Kelvin-Voigt contact."""
        elastic = k * self._positive(d)
        if rate is None:
            return elastic
        damper = self.mesh_damping * rate
        if self.backlash == "exact":
            # Not clipped at 0 (a Kelvin-Voigt contact: the damper may pull while the flanks
            # separate faster than the spring relaxes). A clipped force, max(k d + c d', 0), made
            # jax.jacfwd of one scalar (a vmap of size 1 around the integration loops) wrong even
            # at ζ = 0 (d DTE/d torque 2.7× off at 1500 rpm, jax 0.10.2, CPU), though every
            # variant's tangent is the same function; a larger vmap and jax.jvp were right.
            return jnp.where(d > 0.0, elastic + damper, 0.0)
        return elastic + damper * jax.nn.sigmoid(d / self.backlash_width)

    def flank_forces(self, tau, q, v=None, tab=None):
        """(f_d, f_b) (N) at τ for the displacements ``q`` [..., 6] (m): the drive flanks' normal
        force (along LOA1; ≥ 0 but for a mesh damper's pull on separating flanks) and the back
        flanks' (along LOA2; ≤ 0 but for that pull); their sum is the mesh
        force Fm whose moment is rb·Fm. Each is km⟨d⟩ (km_b⟨d_b⟩), with the velocities ``v``
        [..., 6] (m/s) plus the mesh damper (``GearPair.mesh_damping_ratio``) where the flanks
        touch (``_contact_force``); without ``v``, the elastic force alone. ``tab``: the tables
        at τ, if evaluated."""
        km, d, km_b, d_b = self._flanks(tau, q, tab)
        rate, rate_b = (None, None) if v is None else self.flank_rates(tau, v)
        return self._contact_force(km, d, rate), -self._contact_force(km_b, d_b, rate_b)

    def damper_power(self, tau, q, v):
        """Power (W) the mesh damper dissipates at τ for displacements ``q`` and velocities ``v``
        [..., 6] (SI): the damper's part of each flank pair's force (its magnitude less the elastic
        force) times that pair's rate of compression: c d'² where the pair touches, ≥ 0."""
        km, d, km_b, d_b = self._flanks(tau, q)
        rate, rate_b = self.flank_rates(tau, v)
        drive = self._contact_force(km, d, rate) - self._contact_force(km, d, None)
        back = self._contact_force(km_b, d_b, rate_b) - self._contact_force(km_b, d_b, None)
        return drive * rate + back * rate_b

    def load_torque(self, s):
        """T2 (N m) for the correction s."""
        return self.torque * self.base_radius[1] / self.base_radius[0] * (1.0 + s)

    def physical(self, z):
        """(q [m], dq/dt [m/s]) from the scaled state z[..., 12]."""
        q = z[..., :6] * LENGTH_SCALE
        v = z[..., 6:] * (LENGTH_SCALE / self.mesh_period)
        return q, v

    def mesh_deflection(self, q, e):
        """r1φ1 + y1 − r2φ2 − y2 − e (m): εd for e = 0, the drive flanks' compression for e(τ)."""
        return q[..., 0] + q[..., 1] - q[..., 3] - q[..., 4] - e

    def _forces_and_damper_power(self, tau, q, v, tab):
        """(f_d, f_b, P): ``flank_forces`` with the velocities, and ``damper_power``, from one
        evaluation of the flanks' compressions and rates at τ (``tab``: the tables at τ)."""
        km, d, km_b, d_b = self._flanks(tau, q, tab)
        rate, rate_b = self.flank_rates(tau, v)
        elastic, elastic_b = self._contact_force(km, d, None), self._contact_force(km_b, d_b, None)
        drive, back = self._contact_force(km, d, rate), self._contact_force(km_b, d_b, rate_b)
        power = (drive - elastic) * rate + (back - elastic_b) * rate_b
        return drive, -back, power

    def accelerations(self, tau, q, v, s):
        """d²q/dt² (m/s²) of paper Eq. (1) at time fraction τ."""
        return self._accelerations_and_damper_power(tau, q, v, s)[0]

    def _accelerations_and_damper_power(self, tau, q, v, s):
        """(d²q/dt² in m/s², the mesh damper's power in W) at time fraction τ."""
        tab = self.tables(tau)
        rb = self.base_radius
        dphi1 = v[0] / rb[0]
        dphi2 = v[3] / rb[1]
        f_drive, f_back, power = self._forces_and_damper_power(tau, q, v, tab)
        fm = f_drive + f_back
        # the back force acts along LOA2: cos 2α_w of it along y, sin 2α_w along x
        c, s_back = self.back_direction()
        fy = f_drive + c * f_back
        fx = s_back * f_back
        # OLOA mesh damping on the vibratory sliding velocity (module docstring).
        dx1, dx2 = v[2], v[5]
        fd = -(tab[_C1] * dphi1 - tab[_C0] * dx1 - tab[_C2] * dphi2 + tab[_C0] * dx2)
        fd_r1 = -(tab[_C11] * dphi1 - tab[_C1] * dx1 - tab[_C12] * dphi2 + tab[_C1] * dx2)
        fd_r2 = -(tab[_C12] * dphi1 - tab[_C2] * dx1 - tab[_C22] * dphi2 + tab[_C2] * dx2)
        t1 = self.torque
        t2 = self.load_torque(s)
        m, j = self.mass, self.inertia
        ddphi1 = (t1 + tab[_F1R] + fd_r1 - self.ct[0] * dphi1 - rb[0] * fm) / j[0]
        ddy1 = (-self.cy[0] * v[1] - self.ky[0] * q[1] - fy) / m[0]
        ddx1 = (-self.cx[0] * v[2] - self.kx[0] * q[2] - (tab[_F1] + fd) + fx) / m[0]
        ddphi2 = (-t2 - tab[_F2R] - fd_r2 - self.ct[1] * dphi2 + rb[1] * fm) / j[1]
        ddy2 = (-self.cy[1] * v[4] - self.ky[1] * q[4] + fy) / m[1]
        ddx2 = (-self.cx[1] * v[5] - self.kx[1] * q[5] + (tab[_F2] + fd) - fx) / m[1]
        return jnp.stack([rb[0] * ddphi1, ddy1, ddx1, rb[1] * ddphi2, ddy2, ddx2]), power

    def __call__(self, tau, z, s):
        return self.rate_and_damper_power(tau, z, s)[0]

    def rate_and_damper_power(self, tau, z, s):
        """(dz/dτ of the scaled state [12], the mesh damper's power in W) at time fraction τ:
        the vector field, and the integrand of the damper's mean power ∫₀¹ P dτ."""
        q, v = self.physical(z)
        a, power = self._accelerations_and_damper_power(tau, q, v, s)
        return jnp.concatenate([z[6:], a * (self.mesh_period**2 / LENGTH_SCALE)]), power


def build_dynamics(
    pair, op, mesh, interface: MeshInterface, options: DynamicsOptions
) -> GearDynamics:
    """Assemble Eq. (1)'s parameters from the gear pair, operating point, mesh cycle and interface."""
    if interface.n_positions != mesh.n_positions:
        raise ValueError(
            f"MeshInterface has {interface.n_positions} positions but the MeshCycle has "
            f"{mesh.n_positions}; they must match"
        )
    geo = gear_geometry(pair)
    rb = geo.base_radius
    z1, z2 = pair.teeth
    channels = interface_channels(mesh, interface)
    omega1 = op.speed_rpm * (2.0 * jnp.pi / 60.0)
    b = pair.bearings
    mesh_period = 2.0 * jnp.pi / (z1 * omega1)
    f_max = _highest_natural_frequency(pair, rb, jnp.max(mesh.mesh_stiffness))
    n_steps = jnp.maximum(
        options.steps_per_period, jnp.ceil(options.steps_per_mode_period * f_max * mesh_period)
    )
    # c = 2ζ √(k̄m me): ζ of the mesh mode of two rotors on a spring k̄m (GearPair docstring)
    me = pair.blank_inertia / rb**2
    mesh_damping = (
        2.0
        * pair.mesh_damping_ratio
        * jnp.sqrt(jnp.mean(mesh.mesh_stiffness) * me[0] * me[1] / (me[0] + me[1]))
    )
    return GearDynamics(
        base_radius=rb,
        inertia=pair.blank_inertia,
        mass=pair.blank_mass,
        ky=b.ky,
        cy=b.cy,
        kx=b.kx,
        cx=b.cx,
        ct=b.ct,
        half_clearance=0.5 * pair.backlash,
        torque=op.torque,
        mesh_period=mesh_period,
        step=1.0 / n_steps,
        omega=jnp.stack([omega1, omega1 * z1 / z2]),
        tables=PeriodicSpline(channels),
        # km and e alone, read at the mirrored phase (an evaluation of all 12 channels there cost
        # the dynamics ~15 %)
        back_tables=PeriodicSpline(channels[:, : _E + 1]),
        back_phase=back_flank_phase(pair, 0.0),
        back_angle=(
            2.0 * geo.operating_pressure_angle
            if options.back_flank == "mirrored"
            else jnp.zeros_like(geo.operating_pressure_angle)
        ),
        backlash_width=options.backlash_width,
        mesh_damping=mesh_damping,
        backlash=options.backlash,
        back_flank=options.back_flank,
    )


def _highest_natural_frequency(pair, rb, km):
    """Largest undamped natural frequency (Hz) of the linearised model at mesh stiffness km."""
    m, j, b = pair.blank_mass, pair.blank_inertia, pair.bearings
    mass = jnp.stack([j[0], m[0], m[0], j[1], m[1], m[1]])
    g = jnp.stack([rb[0], 1.0, 0.0, -rb[1], -1.0, 0.0])
    k = km * jnp.outer(g, g) + jnp.diag(jnp.stack([0.0, b.ky[0], b.kx[0], 0.0, b.ky[1], b.kx[1]]))
    s = 1.0 / jnp.sqrt(mass)
    lam = jnp.linalg.eigvalsh(k * s[:, None] * s[None, :])
    return jnp.sqrt(jnp.max(lam)) / (2.0 * jnp.pi)
