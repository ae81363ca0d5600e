"""One mesh period of the gear dynamics by a fixed-step explicit Runge-Kutta method.

The periodic steady state is found by shooting over one mesh period, so the integration over a
period is the dynamics' one hot kernel: Newton evaluates it at every iteration, its forward-mode
Jacobian gives the Newton matrix and the monodromy, and its derivative with respect to the model's
parameters gives the orbit's implicit derivative. It is written here as a fixed-length
``lax.scan`` over blocks of steps, so that it is differentiable in both modes (forward, and
reverse: a scan transposes, a while loop with a data-dependent trip count does not) and is traced
once wherever it is used.

The step count follows the speed: at least ``DynamicsOptions.steps_per_period`` steps, more at low
speed where one mesh period spans many periods of the highest natural frequency
(``GearDynamics.step``). It is rounded up to a whole number of blocks of ``block_steps`` steps
(a multiple of the M mesh positions, so every position is a step boundary and its state is a step's
end, not an interpolation). The scan runs over ``max_blocks`` blocks, each behind a ``lax.cond``
that skips it beyond the point's own count: a skipped block costs a few tens of nanoseconds on a
CPU. Under ``vmap`` the skip is decided on the largest count of the batch (``batch_max``), so it
stays a real branch (a batched predicate would make it a select that runs every block for every
member), and each member's own count masks the blocks past it: a batch costs what its slowest
member needs, and each member's result is the one it has alone. Each block is checkpointed, so a
reverse pass stores one state per block, not one per stage.

The Butcher tableau is that of a diffrax explicit Runge-Kutta solver (``diffrax.Tsit5`` by default,
``DynamicsOptions.solver``): the method is diffrax's, the loop is this module's.

Alongside the 12 scaled states the integration carries the mesh damper's dissipated energy, the
integral of its power over the period (a quadrature by the same method), so the mean damper power
is exact to the integrator's order instead of sampled.
"""

from __future__ import annotations

import math

import diffrax
import equinox as eqx
import jax
import jax.custom_batching
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float, Int

from .model import DynamicsOptions, GearDynamics


class PeriodFlow(eqx.Module):
    """The dynamics over one mesh period from a start ``w`` = [z0 (12), s].

    Attributes:
        final: scaled state z(τ = 1) [12].
        positions: scaled states at the M mesh positions τ_i = i/M [M, 12] (row 0 is z0).
        damper_power: mean power the mesh damper dissipates over the period, W (∫₀¹ P dτ).
    """

    final: Float[Array, " 12"]
    positions: Float[Array, "M 12"]
    damper_power: Float[Array, ""]


@jax.custom_batching.custom_vmap
def batch_max(n):
    """``n`` itself; under ``vmap``, the largest ``n`` of the batch, unbatched (so that a branch
    taken on it stays a branch in the batched program)."""
    return n


@batch_max.def_vmap
def _batch_max_rule(axis_size, in_batched, n):
    del axis_size
    (batched,) = in_batched
    return (jnp.max(n, axis=0) if batched else n), False


def tableau_of(options: DynamicsOptions):
    """The Butcher tableau of the options' solver (default ``diffrax.Tsit5``)."""
    solver = diffrax.Tsit5() if options.solver is None else options.solver
    tableau = getattr(type(solver), "tableau", None)
    if tableau is None or getattr(tableau, "a_lower", None) is None:
        raise ValueError(
            f"DynamicsOptions.solver = {solver!r} is not valid; valid: an explicit Runge-Kutta "
            "solver of diffrax with a Butcher tableau (Tsit5, Dopri5, Dopri8, Heun, Bosh3, ...)"
        )
    return tableau


def block_steps(options: DynamicsOptions, n_positions: int) -> int:
    """Steps per block: ``steps_per_period`` rounded up to a multiple of the M mesh positions."""
    return n_positions * max(1, math.ceil(options.steps_per_period / n_positions))


def max_blocks(options: DynamicsOptions, n_positions: int) -> int:
    """Blocks the scan runs over: ``max_steps_per_period`` in whole blocks."""
    return max(1, math.ceil(options.max_steps_per_period / block_steps(options, n_positions)))


def blocks_needed(dyn: GearDynamics, options: DynamicsOptions, n_positions: int) -> Int[Array, ""]:
    """Blocks this point needs: its step count (``dyn.step``) in whole blocks, ≥ 1 (int32)."""
    per = block_steps(options, n_positions)
    steps = jnp.round(1.0 / jax.lax.stop_gradient(dyn.step))
    return jnp.maximum(jnp.ceil(steps / per), 1.0).astype(jnp.int32)


def _rk_step(dyn: GearDynamics, tableau, t, y, s, h):
    """One explicit RK step of the augmented state y = [z (12), E] from τ = t (returns y_new).

    The stages run in a loop over one evaluation of the vector field (traced once, not once per
    stage: the field is most of the program). Stages after the last nonzero weight of ``b_sol``
    are not evaluated (FSAL stages)."""
    b = np.asarray(tableau.b_sol, dtype=float)
    used = int(np.nonzero(b)[0].max()) + 1
    a = np.zeros((used, used))
    for i in range(1, used):
        row = np.asarray(tableau.a_lower[i - 1], dtype=float)
        a[i, : row.shape[0]] = row
    c = np.concatenate([[0.0], np.asarray(tableau.c, dtype=float)[: used - 1]])
    a, b, c = (jnp.asarray(x, dtype=y.dtype) for x in (a, b[:used], c))

    def stage(i, ks):
        yi = y + h * (a[i] @ ks)
        dz, power = dyn.rate_and_damper_power(t + c[i] * h, yi[:12], s)
        return ks.at[i].set(jnp.concatenate([dz, power[None]]))

    ks = jax.lax.fori_loop(0, used, stage, jnp.zeros((used, y.shape[0]), y.dtype))
    return y + h * (b @ ks)


def period_flow(dyn: GearDynamics, w, options: DynamicsOptions, n_positions: int) -> PeriodFlow:
    """Integrate one mesh period from ``w`` = [z0 (12), s] (``PeriodFlow``).

    The point's step count is its blocks (``blocks_needed``) × ``block_steps``; beyond
    ``max_blocks`` (speeds so low that ``max_steps_per_period`` is not enough) the result is NaN,
    reported as not finite by the caller. Differentiable in every input, in both modes."""
    tableau = tableau_of(options)
    per_block = block_steps(options, n_positions)
    k_max = max_blocks(options, n_positions)
    stride_base = per_block // n_positions  # steps between positions in a one-block period
    n_blocks = blocks_needed(dyn, options, n_positions)
    bound = batch_max(n_blocks)
    too_many = n_blocks > k_max
    n_eff = jnp.minimum(n_blocks, k_max)
    h = 1.0 / (n_eff * per_block).astype(dyn.step.dtype)
    stride = n_eff * stride_base
    z0, s = w[:12], w[12]
    y0 = jnp.concatenate([z0, jnp.zeros((1,), z0.dtype)])
    positions0 = jnp.zeros((n_positions, 12), z0.dtype).at[0].set(z0)

    @jax.checkpoint
    def run_block(k, y):
        def step(y, j):
            g = k * per_block + j  # global step index
            return _rk_step(dyn, tableau, g * h, y, s, h), y

        y_end, ys = jax.lax.scan(step, y, jnp.arange(per_block))
        return y_end, ys  # ys[j]: the state at the start of step j of the block

    def block(carry, k):
        y, positions = carry

        def run(op):
            y, positions = op
            y_end, ys = run_block(k, y)
            g = k * per_block + jnp.arange(per_block)
            rows = jnp.where(g % stride == 0, g // stride, n_positions)  # out of range: dropped
            positions = positions.at[rows].set(ys[:, :12], mode="drop")
            live = k < n_eff  # this member's own count (the branch runs up to the batch's)
            return jnp.where(live, y_end, y), jnp.where(live, positions, op[1])

        return jax.lax.cond(k < bound, run, lambda op: op, (y, positions)), None

    (y1, positions), _ = jax.lax.scan(block, (y0, positions0), jnp.arange(k_max))
    nan = jnp.asarray(jnp.nan, y1.dtype)
    return PeriodFlow(
        final=jnp.where(too_many, nan, y1[:12]),
        positions=jnp.where(too_many, nan, positions),
        damper_power=jnp.where(too_many, nan, y1[12]),
    )
