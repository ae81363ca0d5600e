"""An implicit adjoint for optimistix whose failed linear solve gives NaN, not an exception.

``optx.ImplicitAdjoint`` differentiates a converged root or fixed point by the implicit function
theorem, solving one linear system per tangent with lineax; lineax raises (from inside the
transformation, an ``EquinoxRuntimeError``) when that solve fails or meets a non-finite
right-hand side. In the coupled model that turns a derivative that does not exist (a singular
I − ∂T/∂x, a NaN input tangent) into a crash of the caller's ``jax.grad``. ``NaNImplicitAdjoint``
is the same rule with the solve's failure left in its value: with a solver that returns NaN where
it fails (``EarlyExitGMRES(nan_on_failure=True)``) the tangent is NaN, and the primal result is
untouched. It transposes as lineax's solve does (the transposed solve is the same solver's, told
that its unknowns are cotangents: ``EarlyExitGMRES`` scales them by the root's inverse magnitudes),
so reverse mode is as accurate as forward mode.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import jax.tree_util as jtu
import lineax as lx
import optimistix as optx


def _bounded_while(cond_fun, body_fun, init_val, *, max_steps=None, buffers=None):
    """A while loop with an optional cap on its iterations (what optimistix's iterate expects of
    the loop its adjoint provides), on ``lax.while_loop``: the primal is never differentiated
    through its iterations."""
    del buffers
    if max_steps is None:
        return jax.lax.while_loop(cond_fun, body_fun, init_val)

    def cond(carry):
        return cond_fun(carry[0]) & (carry[1] < max_steps)

    def body(carry):
        return body_fun(carry[0]), carry[1] + 1

    return jax.lax.while_loop(cond, body, (init_val, jnp.asarray(0)))[0]


class NaNImplicitAdjoint(optx.AbstractAdjoint):
    """``optx.ImplicitAdjoint`` whose failed linear solve gives NaN tangents (module docstring).

    Attributes:
        linear_solver: the lineax solver of (∂F/∂root) v = −∂F/∂θ·θ̇.
    """

    linear_solver: lx.AbstractLinearSolver

    def apply(self, primal_fn, rewrite_fn, inputs, tags):
        inputs = inputs + (_bounded_while,)
        root, residual = _implicit(primal_fn, rewrite_fn, inputs, tags, self.linear_solver)
        return root, jtu.tree_map(jax.lax.stop_gradient, residual)


@eqx.filter_custom_jvp
def _implicit(fn_primal, fn_rewrite, inputs, tags, linear_solver):
    del fn_rewrite, tags, linear_solver
    return jtu.tree_map(jnp.asarray, fn_primal(inputs))


def _is_none(x):
    return x is None


@_implicit.def_jvp
def _implicit_jvp(primals, tangents):
    fn_primal, fn_rewrite, inputs, tags, linear_solver = primals
    t_inputs = tangents[2]
    no_tangent = jtu.tree_map(_is_none, t_inputs, is_leaf=_is_none)
    nondiff, diff = eqx.partition(inputs, no_tangent, is_leaf=_is_none)
    root, residual = _implicit(fn_primal, fn_rewrite, inputs, tags, linear_solver)

    def rewrite(root_, diff_):
        return fn_rewrite(root_, residual, eqx.combine(diff_, nondiff))

    # One linearisation at the root gives both the operator ∂F/∂root and the right-hand side
    # ∂F/∂θ·θ̇: the map F (the fixed point's whole step, with its periodic-orbit solve) is evaluated
    # once for the derivative, not once per use, and the Krylov products are linear maps of stored
    # residuals, not new evaluations of F.
    _, linear = jax.linearize(rewrite, root, diff)
    zero_root = jtu.tree_map(jnp.zeros_like, root)
    zero_diff = jtu.tree_map(jnp.zeros_like, diff)

    def matvec(v):
        return linear(v, zero_diff)

    def solve(mv, b, transposed=False):
        # throw=False: a solver that fails says so in its value (EarlyExitGMRES(nan_on_failure=
        # True) returns NaN); lineax would raise on it, from inside the transformation.
        # transposed: the unknowns are cotangents of the root, scaled by its inverse magnitudes
        # (EarlyExitGMRES); scaled as tangents, the residual on the leaves of large magnitude
        # counts for almost nothing and reverse mode stops short of forward mode's accuracy.
        operator = lx.FunctionLinearOperator(mv, jax.eval_shape(lambda: b), tags=tags)
        options = {"scale_point": root, "transposed": transposed}
        return lx.linear_solve(operator, b, linear_solver, options=options, throw=False).value

    def transpose_solve(mv, b):
        return solve(mv, b, transposed=True)

    rhs = linear(zero_root, t_inputs)
    # Parts of the right-hand side that no input tangent reaches (the state's non-differentiated
    # parts) come out as constant zeros; custom_linear_solve transposes only a right-hand side
    # that is linear throughout, so each leaf gets a zero that is (0 × the sum of the others).
    leaves = jtu.tree_leaves(rhs)
    if leaves:
        anchor = 0.0 * sum(jnp.sum(leaf) for leaf in leaves)
        rhs = jtu.tree_map(lambda leaf: leaf + anchor.astype(leaf.dtype), rhs)
    # custom_linear_solve: JAX transposes it by solving with the transposed operator (the same
    # solver), where lineax's own transpose would raise on a failed solve
    solution = jax.lax.custom_linear_solve(matvec, rhs, solve, transpose_solve=transpose_solve)
    t_root = jtu.tree_map(lambda x: -x, solution)
    t_residual = jax.custom_derivatives.zero_from_primal(residual, symbolic_zeros=True)
    return (root, residual), (t_root, t_residual)
