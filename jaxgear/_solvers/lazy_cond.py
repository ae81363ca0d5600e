"""A ``lax.cond`` that stays lazy under ``vmap``.

A vmapped ``lax.cond`` with a batched predicate becomes a select: both branches run for every
member. That made a vmapped batch of EHL contacts pay for every fallback attempt of the solver
(benchmarks/ehl_kernel.py), and would make every point of a vmapped speed sweep pay for the
attractor integration that only the points without a stable periodic orbit need
(``tribodynamics.second_pass.attractor_means``).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.custom_batching
import jax.numpy as jnp


def cond_any_member(
    pred, true_fn, false_fn, operand, *, all_true_path: bool = True, mixed: str = "select"
):
    """``lax.cond(pred, true_fn, false_fn, operand)`` that stays lazy under ``vmap``.

    Under vmap, ``true_fn`` runs (batched) only when some member's predicate is true, and
    ``false_fn`` only when some member's is false; nested vmaps recurse. When the predicates are
    mixed, both run for every member (a select), as plain vmap would, or (``mixed="map"``) each
    member runs its own branch, one after another.

    The branches must read only ``operand`` (batched values closed over are refused by
    custom_vmap); static values (Python objects, static Module fields) may be closed over.
    Differentiated, it is the plain ``lax.cond`` (and so not lazy under vmap).

    Args:
        all_true_path: under vmap, run ``true_fn`` alone (not the select) when every member takes
            it. That traces ``true_fn`` twice; pass False where it is expensive to compile and
            rarely taken by a whole batch.
        mixed: what a batch whose predicates are mixed does. "select": both branches for every
            member, batched (as plain vmap; right where the branches vectorise well). "map": one
            member after another (``lax.map``), each a real cond, so only the members that take
            a branch run it, unbatched: right for a long sequential branch (a time integration)
            that few members of a large batch take, where the batched select would run it for
            all of them.
    """
    if mixed not in ("select", "map"):
        raise ValueError(f"mixed = {mixed!r} is not valid; valid choices: 'select', 'map'")
    arrays, static = eqx.partition(operand, eqx.is_array)
    # a flat list of arrays: the JVP-of-vmap path of custom_vmap mishandles None leaves
    leaves, treedef = jax.tree.flatten(arrays)

    def branch(fn):
        return lambda a: fn(eqx.combine(jax.tree.unflatten(treedef, a), static))

    @jax.custom_batching.custom_vmap
    def run(pred, arrays):
        return jax.lax.cond(pred, branch(true_fn), branch(false_fn), arrays)

    @run.def_vmap
    def rule(axis_size, in_batched, pred, arrays):
        def widen(x, batched):
            return x if batched else jnp.broadcast_to(x, (axis_size, *jnp.shape(x)))

        pred = widen(pred, in_batched[0])
        arrays = jax.tree.map(widen, arrays, in_batched[1])

        def each(pa):
            if mixed == "map":
                # nested vmaps stay lazy: each member's cond is this one again
                return jax.lax.map(
                    lambda m: cond_any_member(
                        m[0],
                        branch(true_fn),
                        branch(false_fn),
                        m[1],
                        all_true_path=False,
                        mixed="map",
                    ),
                    pa,
                )
            return jax.vmap(lambda p, a: jax.lax.cond(p, branch(true_fn), branch(false_fn), a))(*pa)

        def only(fn):
            return lambda pa: jax.vmap(branch(fn))(pa[1])

        some = lambda pa: cond_any_member(jnp.any(pa[0]), each, only(false_fn), pa)  # noqa: E731
        if all_true_path:
            out = cond_any_member(jnp.all(pred), only(true_fn), some, (pred, arrays))
        else:
            out = some((pred, arrays))
        return out, jax.tree.map(lambda _: True, out)

    # Under differentiation the plain cond (custom_vmap's own JVP rule recurses without end here)
    @jax.custom_jvp
    def lazy(pred, leaves):
        return run(pred, leaves)

    @lazy.defjvp
    def lazy_jvp(primals, tangents):
        pred, leaves = primals
        return jax.jvp(
            lambda a: jax.lax.cond(pred, branch(true_fn), branch(false_fn), a),
            (leaves,),
            (tangents[1],),
        )

    return lazy(jnp.asarray(pred), leaves)
