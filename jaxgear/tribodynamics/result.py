"""The coupled model's result: ``SimulationResult``, its status codes and its assembly."""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

from ..contact.base import safe_sqrt
from ..dynamics.response import dte_harmonic_amplitudes
from ..material import reduced_modulus
from ..power_loss import cycle_mean, efficiency, total_per_position
from ..results import MESSAGES, Status, message

# Status codes of a simulation (``results.Status``; 0 is success; the first failure found, in this
# order, is reported).
STATUS_OK = Status.OK
STATUS_FIXED_POINT = Status.FIXED_POINT  # tribo-dynamic fixed point did not reach its tolerance
STATUS_DYNAMICS = Status.DYNAMICS  # periodic orbit not converged or unstable
STATUS_CONTACT = Status.CONTACT  # a contact solve did not converge
STATUS_NON_FINITE = Status.NON_FINITE
STATUS_ATTRACTOR = Status.ATTRACTOR  # no stable periodic orbit: means over the attractor
STATUS_PENDING = Status.PENDING  # first pass only: the orbit strikes the back flanks
#: The codes a SimulationResult can carry → their messages.
STATUS_NAMES = {
    int(code): MESSAGES[code]
    for code in (
        STATUS_OK,
        STATUS_FIXED_POINT,
        STATUS_DYNAMICS,
        STATUS_CONTACT,
        STATUS_NON_FINITE,
        STATUS_ATTRACTOR,
        STATUS_PENDING,
    )
}


class SimulationResult(eqx.Module):
    """The tribo-dynamic (or quasi-static) solution over one mesh cycle (SI; M positions, 2 pair slots).

    Attributes:
        power_loss: Φ̄, cycle-mean mesh power loss, W (paper Eq. 17).
        power_loss_sliding, power_loss_rolling: its sliding and rolling parts, W.
        efficiency: Ψ = 1 − Φ̄/(T1 ω1).
        dte_rms: RMS dynamic transmission error over the first 10 mesh harmonics, m (REFERENCE §7 R1);
            quasi-static: of the static TE.
        power_loss_position: Φ(t_i), W [M]; power_loss_pair: Φn(t_i), W [M, 2] (and its sliding and
            rolling parts power_sliding_pair, power_rolling_pair).
        tooth_force: W_T per pair, N [M, 2]; surface_velocity: uj per [position, pair, gear], m/s.
        hertz_pressure: Hertz pressure of W_T per pair, Pa [M, 2].
        friction_coefficient: per pair [M, 2]; damping: cm per pair, N s/m [M, 2].
        dynamic_te: εd(t_i), m [M]; roll_angle: gear 1 roll angle of slot 0, rad [M].
        status: 0 ok, else the first failure (``jaxgear.results.Status``, ``STATUS_NAMES``); converged
            (a property): status 0;
            6 (STATUS_ATTRACTOR): the fixed point has no stable periodic orbit, and the values are
            means over the attractor the gears settle on (``Fidelity.attractor_periods``);
        fixed_point_residual: |T(y) − y| of the friction table F1 relative to its maximum, in the
            last fixed-point evaluation;
        fixed_point_iterations: iterations used (0 for quasi-static).
        failed_contacts: loaded contacts of the cycle whose EHL solve failed (status 3); their
            outputs are carried over from the nearest good contact of the engagement, never used as
            they came out.
        power_loss_back: the back flanks' part of Φ̄ (and of its sliding and rolling parts and
            Φ(t)), W: where rattling teeth strike the back flanks, on the attractor (status 6) or
            on a periodic orbit, their contacts on the mirrored line of action
            (``_back_flank_power``); 0 elsewhere.
        back_contact_share: share of the mesh cycle with back-flank contact (the mesh deflection
            past the backlash, negative tooth forces; on status 6 over every recorded cycle of the
            attractor). 0 when quasi-static.
        mesh_damping_power: mean power the viscous mesh damper along the line of action
            dissipates, W (``GearPair.mesh_damping_ratio``; 0 without it, and when quasi-static):
            vibration energy turned into heat in the mesh, not friction, so not part of Φ̄ or Ψ
            (the paper's loss is the friction's; neither are the bearings' and torsional
            dampers'). On status 6 the attractor record's mean.
    """

    power_loss: Float[Array, ""]
    power_loss_sliding: Float[Array, ""]
    power_loss_rolling: Float[Array, ""]
    efficiency: Float[Array, ""]
    dte_rms: Float[Array, ""]
    power_loss_position: Float[Array, " M"]
    power_loss_pair: Float[Array, "M 2"]
    power_sliding_pair: Float[Array, "M 2"]
    power_rolling_pair: Float[Array, "M 2"]
    tooth_force: Float[Array, "M 2"]
    surface_velocity: Float[Array, "M 2 2"]
    hertz_pressure: Float[Array, "M 2"]
    friction_coefficient: Float[Array, "M 2"]
    damping: Float[Array, "M 2"]
    dynamic_te: Float[Array, " M"]
    roll_angle: Float[Array, " M"]
    status: Int[Array, ""]
    fixed_point_residual: Float[Array, ""]
    fixed_point_iterations: Int[Array, ""]
    failed_contacts: Int[Array, ""]
    power_loss_back: Float[Array, ""]
    back_contact_share: Float[Array, ""]
    mesh_damping_power: Float[Array, ""]

    @property
    def converged(self) -> Bool[Array, "..."]:
        """Everything converged: ``status`` is 0 (elementwise over a batch)."""
        return self.status == STATUS_OK

    @property
    def message(self) -> str:
        """The status in words (a single result)."""
        return message(self.status)


def hertz_pressure_of(pair, mesh, load):
    w = jnp.maximum(load, 0.0) / pair.face_width
    return safe_sqrt(w * reduced_modulus(*pair.materials) / (2.0 * jnp.pi * mesh.reduced_radius))


def _back_contact_share(load):
    """Share of the positions of one cycle's tooth forces ``load`` [..., M, 2] whose mesh force
    (their sum) is negative: back-flank contact."""
    return jnp.mean((jnp.sum(load, axis=-1) < 0.0).astype(load.dtype))


def assemble(
    pair, op, mesh, forces, load, velocity, dte, status, residual, iterations, back=None, damper=0.0
):
    """The SimulationResult; ``back``: (back_contact_share, (sliding, rolling) back-flank power
    per position) of the orbit or the attractor, or None (quasi-static: no back contact);
    ``damper``: the mesh damper's mean power (W)."""
    none = jnp.zeros(mesh.n_positions, dtype=load.dtype)
    back_contact, (back_sliding, back_rolling) = (None, (none, none)) if back is None else back
    power_pair = forces.power_sliding + forces.power_rolling
    sliding = cycle_mean(total_per_position(forces.power_sliding) + back_sliding)
    rolling = cycle_mean(total_per_position(forces.power_rolling) + back_rolling)
    loss = sliding + rolling
    dte_rms = jnp.sqrt(jnp.sum(dte_harmonic_amplitudes(dte) ** 2))
    # the tooth forces and the mesh too: a contact solver reads a NaN load as no contact (NaN > 0 is
    # false), so a NaN position would otherwise drop out of Φ̄ silently
    values = jnp.stack(
        [loss, dte_rms, jnp.sum(power_pair), jnp.sum(load), jnp.sum(mesh.mesh_stiffness)]
    )
    status = jnp.where(jnp.all(jnp.isfinite(values)), status, STATUS_NON_FINITE)
    return SimulationResult(
        power_loss=loss,
        power_loss_sliding=sliding,
        power_loss_rolling=rolling,
        efficiency=efficiency(loss, op.torque, op.omega1),
        dte_rms=dte_rms,
        power_loss_position=total_per_position(power_pair) + back_sliding + back_rolling,
        power_loss_pair=power_pair,
        power_sliding_pair=forces.power_sliding,
        power_rolling_pair=forces.power_rolling,
        tooth_force=load,
        surface_velocity=velocity,
        hertz_pressure=hertz_pressure_of(pair, mesh, load),
        friction_coefficient=forces.friction_coefficient,
        damping=forces.damping,
        dynamic_te=dte,
        roll_angle=mesh.roll_angle,
        status=jnp.asarray(status, dtype=jnp.int32),
        fixed_point_residual=jnp.asarray(residual, dtype=loss.dtype),
        fixed_point_iterations=jnp.asarray(iterations, dtype=jnp.int32),
        failed_contacts=jnp.asarray(forces.failed, dtype=jnp.int32),
        power_loss_back=cycle_mean(back_sliding + back_rolling),
        back_contact_share=(
            _back_contact_share(load) if back_contact is None else jnp.asarray(back_contact)
        ).astype(loss.dtype),
        mesh_damping_power=jnp.asarray(damper, dtype=loss.dtype),
    )


@jax.custom_jvp
def _nan_tangent_where(x, flag):
    """``x``, whose tangent is NaN where ``flag`` (a float, 1 or 0) is 1 and passes unchanged
    elsewhere: a derivative that does not exist is reported as NaN, not as zero or a part."""
    del flag
    return x


@_nan_tangent_where.defjvp
def _nan_tangent_where_jvp(primals, tangents):
    x, flag = primals
    tx, _ = tangents
    scale = jnp.where(flag > 0.5, jnp.nan, 1.0).astype(tx.dtype)
    return x, scale * tx


def without_derivative_where(result: SimulationResult, flag) -> SimulationResult:
    """``result`` with every floating-point field's derivative NaN where ``flag`` holds.

    Used at status 6: the attractor's means are not smooth functions of the design (the operand
    of the attractor branch is cut from the trace), so without this a ``jax.jvp``/``jax.jacfwd``
    of Ψ there would silently be the part that does not pass through the dynamics (Ψ's T1 ω1, the
    mesh geometry), neither zero nor the derivative. Values are unchanged."""
    f = jnp.asarray(flag, dtype=result.power_loss.dtype)

    def mark(leaf):
        if eqx.is_inexact_array(leaf):
            return _nan_tangent_where(leaf, f)
        return leaf

    return jax.tree_util.tree_map(mark, result)
