# ruff: noqa: F722  (jaxtyping shape strings)
"""Cheap friction models: the constant-μ and regression-formula rungs of the fidelity ladder.

DESIGN §4 (friction axis: constant μ → regression formula → smooth EHL → mixed EHL). All models
share one interface, :meth:`FrictionModel.coefficient`, in SI units:

    coefficient(hertz_pressure [Pa], slide_to_roll [-], entraining_velocity [m/s],
                inlet_viscosity [Pa s], reduced_radius [m], composite_roughness [m]) -> μ [-]

with the entraining velocity Ve = u1 + u2 (the rolling-velocity *sum*, as in Xu et al. 2007;
twice the mean rolling velocity ur of paper Eq. 3) and the slide-to-roll ratio
SR = us/ur = 2(u1 − u2)/(u1 + u2). Arguments broadcast: a whole mesh cycle is evaluated at once.
"""

from __future__ import annotations

import abc

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

from .._validation import check_finite, check_non_negative, check_positive


def smooth_sign(x, width):
    """sgn(x) smoothed over ``width`` (same units as x): x/(x² + width²)^½, odd and C∞; the sign
    of the sliding speed in every friction rung (a real traction turns over a small slip, too)."""
    return x / jnp.sqrt(x * x + width * width)


# Xu, Kahraman, Anderson & Maddock (2007), J. Mech. Des. 129, 58-69: b1..b9 (REFERENCE §9).
XU_COEFFICIENTS = (
    -8.916465,
    1.03303,
    1.036077,
    -0.354068,
    2.812084,
    -0.100601,
    0.752755,
    -0.390958,
    0.620305,
)


def smooth_abs(x, width):
    """|x| made C¹ at 0: (x² + w²)/(2w) for |x| < w, exactly |x| otherwise (w = ``width`` > 0).

    Equal to |x| to round-off for |x| ≥ w; value w/2 and slope 0 at x = 0, so gradients exist at the
    pitch point (SR = 0).
    """
    ax = jnp.abs(x)
    return jnp.where(ax < width, (x * x + width * width) / (2.0 * width), ax)


def _check_inputs(hertz_pressure, slide_to_roll, entraining_velocity, inlet_viscosity,
                  reduced_radius, composite_roughness):  # fmt: skip
    check_positive("hertz_pressure", hertz_pressure, "Pa")
    check_finite("slide_to_roll", slide_to_roll)
    check_positive("entraining_velocity", entraining_velocity, "m/s")
    check_positive("inlet_viscosity", inlet_viscosity, "Pa s")
    check_positive("reduced_radius", reduced_radius, "m")
    check_non_negative("composite_roughness", composite_roughness, "m")


class FrictionModel(eqx.Module):
    """Abstract friction model: μ of a line contact from its operating state (see module
    docstring)."""

    @abc.abstractmethod
    def coefficient(
        self,
        hertz_pressure,
        slide_to_roll,
        entraining_velocity,
        inlet_viscosity,
        reduced_radius,
        composite_roughness,
    ) -> Float[Array, ...]:
        """Friction coefficient μ (dimensionless), broadcast over the arguments.

        Args:
            hertz_pressure: maximum Hertz pressure ph, Pa (> 0).
            slide_to_roll: SR = 2(u1 − u2)/(u1 + u2), dimensionless (any sign).
            entraining_velocity: Ve = u1 + u2, m/s (> 0).
            inlet_viscosity: dynamic viscosity at the inlet temperature and ambient pressure, Pa s.
            reduced_radius: R with 1/R = 1/R1 + 1/R2, m.
            composite_roughness: σ = √(Rq1² + Rq2²), m (≥ 0).
        """


class ConstantFriction(FrictionModel):
    """μ = ``mu`` everywhere (the cheapest rung). ``mu`` is traced (≥ 0)."""

    mu: Float[Array, ""] = eqx.field(converter=jnp.asarray, default=0.05)

    def __check_init__(self):
        check_non_negative("ConstantFriction.mu", self.mu)

    def coefficient(
        self,
        hertz_pressure,
        slide_to_roll,
        entraining_velocity,
        inlet_viscosity,
        reduced_radius,
        composite_roughness,
    ):
        _check_inputs(hertz_pressure, slide_to_roll, entraining_velocity, inlet_viscosity,
                      reduced_radius, composite_roughness)  # fmt: skip
        shape = jnp.broadcast_shapes(
            *(
                jnp.shape(a)
                for a in (
                    hertz_pressure,
                    slide_to_roll,
                    entraining_velocity,
                    inlet_viscosity,
                    reduced_radius,
                    composite_roughness,
                )
            )
        )
        return jnp.broadcast_to(self.mu, shape)


class XuFriction(FrictionModel):
    """Regression formula of Xu, Kahraman, Anderson & Maddock (2007) (REFERENCE §9):

        μ = e^f · Ph^b2 · |SR|^b3 · Ve^b6 · ν0^b7 · R^b8,
        f = b1 + b4 |SR| Ph log10(ν0) + b5 exp(−|SR| Ph log10(ν0)) + b9 exp(S),

    in the formula's units: Ph in GPa, Ve = u1 + u2 in m/s, ν0 in mPa s (cP), R in m, S in µm. The
    SI inputs of :meth:`coefficient` are converted inside. |SR| is replaced by :func:`smooth_abs`
    (SR, ``smoothing``) so that μ is differentiable at the pitch point; it is exact for |SR| ≥
    ``smoothing``.

    Attributes:
        smoothing: width w of the |SR| smoothing (default 0.02; |SR| in a gear mesh spans ~0-1).
        coefficients: b1..b9 (static tuple; default Xu et al.'s values).
    """

    smoothing: float = eqx.field(static=True, default=0.02)
    coefficients: tuple = eqx.field(static=True, default=XU_COEFFICIENTS)

    def __check_init__(self):
        check_positive("XuFriction.smoothing", self.smoothing)
        if len(self.coefficients) != 9:
            raise ValueError(
                f"XuFriction.coefficients has {len(self.coefficients)} entries; valid: 9 (b1..b9)"
            )

    def coefficient(
        self,
        hertz_pressure,
        slide_to_roll,
        entraining_velocity,
        inlet_viscosity,
        reduced_radius,
        composite_roughness,
    ):
        _check_inputs(hertz_pressure, slide_to_roll, entraining_velocity, inlet_viscosity,
                      reduced_radius, composite_roughness)  # fmt: skip
        b1, b2, b3, b4, b5, b6, b7, b8, b9 = self.coefficients
        ph = jnp.asarray(hertz_pressure) * 1e-9  # Pa → GPa
        nu0 = jnp.asarray(inlet_viscosity) * 1e3  # Pa s → mPa s (cP)
        s = jnp.asarray(composite_roughness) * 1e6  # m → µm
        sr = smooth_abs(jnp.asarray(slide_to_roll), self.smoothing)
        arg = sr * ph * jnp.log10(nu0)
        f = b1 + b4 * arg + b5 * jnp.exp(-arg) + b9 * jnp.exp(s)
        return (
            jnp.exp(f)
            * ph**b2
            * sr**b3
            * jnp.asarray(entraining_velocity) ** b6
            * nu0**b7
            * jnp.asarray(reduced_radius) ** b8
        )


def sliding_power_loss(mu, load_per_width, sliding_velocity):
    """Sliding power loss per unit face width μ w' |us|, W/m (w' in N/m, us = u1 − u2 in m/s)."""
    return mu * load_per_width * jnp.abs(sliding_velocity)


def friction_force(mu, normal_load, sliding_velocity=None):
    """Friction force of a contact, N: μ W (W the normal load, N, or N/m for a force per width).

    With ``sliding_velocity`` (us = u1 − u2, m/s) the sign of us is applied: the force on gear 1's
    surface opposes its motion relative to gear 2, i.e. −μ W sign(us) along +x.
    """
    force = mu * normal_load
    if sliding_velocity is None:
        return force
    return -force * jnp.sign(sliding_velocity)
