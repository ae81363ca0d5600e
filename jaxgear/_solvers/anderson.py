"""Anderson acceleration as an optimistix fixed-point solver.

Anderson (type II) mixing of the last ``memory`` iterates: with residuals f_k = T(y_k) − y_k and
G_k = T(y_k), the next iterate is G_k − ΔG γ − (1 − β)(f_k − ΔF γ), γ = argmin ‖f_k − ΔF γ‖₂
(Tikhonov-regularised). Only the part of the state returned by ``core`` is mixed; the rest of the state
(outputs carried for the caller) is taken from the latest evaluation of T. Being an optimistix solver,
it keeps ``optx.ImplicitAdjoint``: gradients are those of the fixed point, never of the iterations.
"""

from __future__ import annotations

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jax.flatten_util import ravel_pytree
from jaxtyping import Array, Scalar


class _AndersonState(eqx.Module):
    d_f: Array  # [memory, n]
    d_g: Array  # [memory, n]
    prev_f: Array  # [n]
    prev_g: Array  # [n]
    count: Array  # int
    relative_error: Scalar


class Anderson(optx.AbstractFixedPointSolver):
    """Anderson-accelerated fixed-point iteration (see the module docstring).

    Attributes:
        rtol, atol: terminate when max |T(y) − y| / (atol + rtol |T(y)|) < 1 over the core (or over
            ``measure``).
        memory: number of previous iterates mixed (static).
        beta: mixing (damping) parameter in (0, 1].
        regularisation: relative Tikhonov regularisation of the least-squares problem.
        core: y ↦ the pytree to mix (static callable).
        replace_core: (y, core) ↦ y with its core replaced (static callable).
        measure: y ↦ the pytree the termination test is taken on (static callable; default: the
            core, tested element by element). With a measure the test is leaf by leaf, relative to
            the leaf's largest magnitude: max |ΔT| < atol + rtol max |T| per leaf, so tables of
            different units each count in their own scale and entries crossing zero (a friction
            force changing sign at the pitch point) do not demand an absolute accuracy of atol. It
            also lets a part of the core that only warm-starts T (it does not change T's value at
            the fixed point) be mixed without being required to settle.
    """

    rtol: float
    atol: float
    norm: Callable = eqx.field(static=True, default=optx.max_norm)
    memory: int = eqx.field(static=True, default=4)
    beta: float = 1.0
    regularisation: float = 1e-10
    core: Callable = eqx.field(static=True, default=lambda y: y)
    replace_core: Callable = eqx.field(static=True, default=lambda y, c: c)
    measure: Callable | None = eqx.field(static=True, default=None)

    def init(self, fn, y, args, options, f_struct, aux_struct, tags) -> _AndersonState:
        flat, _ = ravel_pytree(self.core(y))
        n = flat.shape[0]
        zeros = jnp.zeros((self.memory, n), flat.dtype)
        return _AndersonState(
            d_f=zeros,
            d_g=zeros,
            prev_f=jnp.zeros(n, flat.dtype),
            prev_g=jnp.zeros(n, flat.dtype),
            count=jnp.array(0),
            relative_error=jnp.array(jnp.inf, flat.dtype),
        )

    def step(self, fn, y, args, options, state: _AndersonState, tags):
        g_y, aux = fn(y, args)
        yc, _ = ravel_pytree(self.core(y))
        gc, unravel = ravel_pytree(self.core(g_y))
        f = gc - yc
        # Push the newest differences into the ring buffer (after the first step).
        slot = (state.count - 1) % self.memory
        have_prev = state.count > 0
        d_f = jnp.where(have_prev, state.d_f.at[slot].set(f - state.prev_f), state.d_f)
        d_g = jnp.where(have_prev, state.d_g.at[slot].set(gc - state.prev_g), state.d_g)
        n_valid = jnp.minimum(state.count, self.memory)
        valid = jnp.arange(self.memory) < n_valid
        a = jnp.where(valid[:, None], d_f, 0.0)
        gram = a @ a.T
        scale = jnp.maximum(jnp.trace(gram), 1e-300)
        eye = jnp.eye(self.memory, dtype=gram.dtype)
        gram = jnp.where(valid[:, None] & valid[None, :], gram, 0.0) + eye * (
            self.regularisation * scale + jnp.where(valid, 0.0, 1.0)
        )
        gamma = jnp.linalg.solve(gram, a @ f)
        gamma = jnp.where(valid, gamma, 0.0)
        mixed = gc - d_g.T @ gamma - (1.0 - self.beta) * (f - a.T @ gamma)
        ok = jnp.all(jnp.isfinite(mixed))
        new_core = unravel(jnp.where(ok, mixed, gc))  # fall back to a plain step if mixing fails
        new_y = self.replace_core(g_y, new_core)
        if self.measure is None:
            err = jnp.max(jnp.abs(f) / (self.atol + self.rtol * jnp.abs(gc)))
        else:  # leaf-wise, relative to each leaf's largest magnitude
            leaves = zip(
                jax.tree_util.tree_leaves(self.measure(y)),
                jax.tree_util.tree_leaves(self.measure(g_y)),
            )
            err = jnp.max(
                jnp.stack(
                    [
                        jnp.max(jnp.abs(b - a)) / (self.atol + self.rtol * jnp.max(jnp.abs(b)))
                        for a, b in leaves
                    ]
                )
            )
        new_state = _AndersonState(
            d_f=d_f, d_g=d_g, prev_f=f, prev_g=gc, count=state.count + 1, relative_error=err
        )
        return new_y, new_state, aux

    def terminate(self, fn, y, args, options, state: _AndersonState, tags):
        return state.relative_error < 1, optx.RESULTS.successful

    def postprocess(self, fn, y, aux, args, options, state, tags, result):
        return y, aux, {}
