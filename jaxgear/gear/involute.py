"""Array formulas of involute spur gearing (SI units, radians).

Pure functions of arrays, shared by the gear pair's derived quantities and checks
(``gear/pair.py``) and by the derived geometry (``gear/geometry.py``); they broadcast over their
arguments, so a per-gear argument of shape (2,) gives a per-gear result. Every one is differentiable
in its float arguments (the square roots are guarded where their argument can vanish).

Conventions as in ``gear/geometry.py``: s is the distance along the line of action (LOA) from T1,
gear 1's base-circle tangency point, towards T2; a gear's own roll angle at a point of its involute
at radius r is ε = √(r² − rb²)/rb. Formulas: ISO 21771 and Litvin & Fuentes, *Gear Geometry and
Applied Theory* (2004), ch. 10.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

_NEWTON_STEPS = 30


def involute(angle: ArrayLike) -> Float[Array, "..."]:
    """inv α = tan α − α (α in rad, any shape)."""
    return jnp.tan(angle) - angle


@jax.custom_jvp
def inverse_involute(value: ArrayLike) -> Float[Array, "..."]:
    """α (rad) with inv α = ``value`` (any shape; 0 < value ≲ 1, i.e. 0 < α ≲ 55°).

    Newton's method (d inv/dα = tan² α) from α0 = ∛(3 value) (inv α ≈ α³/3 for small α), a fixed
    number of steps: exact to round-off over the range. The derivative is the implicit one,
    dα/d value = 1/tan² α, not that of the iterations.
    """
    return _newton_inverse_involute(jnp.asarray(value))


@jax.jit
def _newton_inverse_involute(value):
    # A loop, not unrolled: the geometry is derived wherever it is used, and 30 unrolled steps per
    # use were a tenth of a simulate program. Jitted so that an eager call (the pair's checks on
    # concrete inputs) reuses one compiled loop instead of compiling one per call.
    def newton(_, alpha):
        f = jnp.tan(alpha) - alpha - value
        return jnp.clip(alpha - f / jnp.tan(alpha) ** 2, 1e-9, 1.55)

    alpha = jnp.clip(jnp.cbrt(3.0 * value), 1e-6, 1.5)
    return jax.lax.fori_loop(0, _NEWTON_STEPS, newton, alpha)


@inverse_involute.defjvp
def _inverse_involute_jvp(primals, tangents):
    (value,), (dvalue,) = primals, tangents
    alpha = inverse_involute(value)
    return alpha, dvalue / jnp.tan(alpha) ** 2


def reference_radius(module: ArrayLike, teeth: ArrayLike) -> Float[Array, "..."]:
    """Reference (generating) pitch radius r = m z/2, m."""
    return module * jnp.asarray(teeth, dtype=jnp.result_type(float)) / 2.0


def base_radius(
    module: ArrayLike, teeth: ArrayLike, pressure_angle: ArrayLike
) -> Float[Array, "..."]:
    """Base radius rb = m z cos α/2, m."""
    return reference_radius(module, teeth) * jnp.cos(pressure_angle)


def tip_radius(
    module: ArrayLike, teeth: ArrayLike, addendum_coefficient: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, "..."]:
    """Tip radius ra = m (z/2 + h_a* + x), m (no tip shortening)."""
    return reference_radius(module, teeth) + module * (addendum_coefficient + profile_shift)


def root_radius(
    module: ArrayLike, teeth: ArrayLike, dedendum_coefficient: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, "..."]:
    """Root radius rf = m (z/2 − h_f* + x), m (generation by a rack of dedendum h_f* m)."""
    return reference_radius(module, teeth) - module * (dedendum_coefficient - profile_shift)


def working_pressure_angle(
    pressure_angle: ArrayLike, teeth: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, ""]:
    """Operating pressure angle α_w of the zero-backlash mesh of shifted gears, rad:
    inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2). ``teeth`` and ``profile_shift`` of shape (2,)."""
    z = jnp.asarray(teeth, dtype=jnp.result_type(float))
    x = jnp.asarray(profile_shift)
    inv_w = involute(pressure_angle) + 2.0 * jnp.tan(pressure_angle) * (x[0] + x[1]) / (z[0] + z[1])
    return inverse_involute(inv_w)


def zero_backlash_centre_distance(
    module: ArrayLike, teeth: ArrayLike, pressure_angle: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, ""]:
    """Centre distance of the zero-backlash mesh, a_w = m (z1 + z2)/2 · cos α/cos α_w, m."""
    z = jnp.asarray(teeth, dtype=jnp.result_type(float))
    alpha_w = working_pressure_angle(pressure_angle, teeth, profile_shift)
    return module * (z[0] + z[1]) / 2.0 * jnp.cos(pressure_angle) / jnp.cos(alpha_w)


def operating_pressure_angle(
    base_radius: ArrayLike, centre_distance: ArrayLike
) -> Float[Array, ""]:
    """α_w = arccos((rb1 + rb2)/a_w), rad, of gears with base radii (rb1, rb2) at centre distance a_w."""
    rb = jnp.asarray(base_radius)
    return jnp.arccos((rb[0] + rb[1]) / centre_distance)


def line_of_action_length(base_radius: ArrayLike, centre_distance: ArrayLike) -> Float[Array, ""]:
    """T1T2 = a_w sin α_w, m: the distance between the base-circle tangency points."""
    return centre_distance * jnp.sin(operating_pressure_angle(base_radius, centre_distance))


def base_pitch(base_radius: ArrayLike, teeth: ArrayLike) -> Float[Array, "..."]:
    """Base pitch pb = 2π rb/z (= π m cos α), m."""
    return 2.0 * jnp.pi * base_radius / jnp.asarray(teeth, dtype=jnp.result_type(float))


def _safe_sqrt(x):
    # √x with the derivative 0 (not 0 × ∞) where x ≤ 0 and √ is replaced by 0.
    positive = x > 0.0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, x, 1.0)), 0.0)


def involute_length(radius: ArrayLike, base_radius: ArrayLike) -> Float[Array, "..."]:
    """√(r² − rb²), m: the distance along the line of action from the base-circle tangency point to
    the involute's point at radius r (0 at and below the base circle)."""
    return _safe_sqrt(jnp.square(radius) - jnp.square(base_radius))


def roll_angle(radius: ArrayLike, base_radius: ArrayLike) -> Float[Array, "..."]:
    """Roll angle ε = √(r² − rb²)/rb of the involute point at radius r, rad (0 below the base
    circle)."""
    return involute_length(radius, base_radius) / base_radius


def path_of_contact(
    base_radius: ArrayLike, tip_radius: ArrayLike, centre_distance: ArrayLike
) -> tuple[Float[Array, ""], Float[Array, ""], Float[Array, ""]]:
    """(T1T2, s_start, s_end), m: the line of action's length and the LOA positions of the start
    of contact (gear 2's tip) and of its end (gear 1's tip), gear 1 driving. Arguments per gear of
    shape (2,), the centre distance a scalar."""
    rb, ra = jnp.asarray(base_radius), jnp.asarray(tip_radius)
    t1t2 = line_of_action_length(rb, centre_distance)
    s_end = involute_length(ra[0], rb[0])
    s_start = t1t2 - involute_length(ra[1], rb[1])
    return t1t2, s_start, s_end


def base_half_angle(teeth: ArrayLike, pressure_angle: ArrayLike, profile_shift: ArrayLike):
    """Half the tooth's angular thickness at the base circle, α2 = π/(2z) + inv α + 2 x tan α/z,
    rad."""
    z = jnp.asarray(teeth, dtype=jnp.result_type(float))
    return (
        jnp.pi / (2.0 * z)
        + involute(pressure_angle)
        + 2.0 * profile_shift * jnp.tan(pressure_angle) / z
    )


def reference_tooth_thickness(
    module: ArrayLike, pressure_angle: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, "..."]:
    """Circular tooth thickness at the reference circle, s = m (π/2 + 2 x tan α), m."""
    return module * (jnp.pi / 2.0 + 2.0 * profile_shift * jnp.tan(pressure_angle))


def undercut_limit(
    pressure_angle: ArrayLike, addendum_coefficient: ArrayLike, profile_shift: ArrayLike
) -> Float[Array, "..."]:
    """Fewest teeth a rack generates without undercut, z_min = 2 (h_a* − x)/sin² α (real-valued)."""
    return 2.0 * (addendum_coefficient - profile_shift) / jnp.sin(pressure_angle) ** 2
