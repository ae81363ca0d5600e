"""Physics-agnostic sweep engine: vmapped chunks, device sharding, checkpoint/resume, per-point status.

``run_points(point_fn, inputs, ...)`` evaluates ``point_fn`` on every row of a batch of inputs (a pytree
of arrays with a leading axis N), optionally with unbatched ``args`` shared by all points. Work is cut
into chunks; each chunk is vmapped and jitted once (all chunks share one shape: the last one is padded),
optionally sharded over devices along the batch axis with ``jax.sharding``, and, with a
``checkpoint_dir``, written to disk as soon as it finishes so an interrupted sweep resumes without
recomputing finished chunks. A chunk that raises, or a point whose
outputs are not finite, is marked failed in the per-point status while every good point is kept.

``run_continuation(step_fn, carry0, inputs, ...)`` does the same for sequential sweeps (``lax.scan``
carrying a state from point to point, e.g. the dynamic state across speeds), with the carry saved
with each chunk.

With ``args``, the point (step) function takes them as its last argument instead of closing over them,
and its compiled chunk is kept per function: a second sweep with the same function and shapes (another
torque, lubricant, surface finish...) reuses it instead of compiling again. The checkpoint fingerprint
covers ``args`` too, so a resumed sweep never picks up chunks computed for other shared inputs.
"""

from __future__ import annotations

import functools
import hashlib
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

# Per-point status codes.
OK = 0
NOT_CONVERGED = 1
NON_FINITE = 2
FAILED = 3
STATUS_NAMES = {
    OK: "ok",
    NOT_CONVERGED: "not converged",
    NON_FINITE: "non-finite",
    FAILED: "failed",
}


class SweepOutput(eqx.Module):
    """Stacked outputs of a sweep (leading axis N) with a per-point status.

    Attributes:
        outputs: pytree of arrays [N, ...]; entries of failed points are NaN (float) or 0 (other).
        status: int array [N]: 0 ok, 1 not converged, 2 non-finite outputs, 3 the chunk raised.
        messages: per failed chunk, the error text (tuple of str; static).
    """

    outputs: Any
    status: np.ndarray
    messages: tuple[str, ...] = eqx.field(static=True, default=())

    @property
    def ok(self) -> np.ndarray:
        return np.asarray(self.status) == OK

    def summary(self) -> dict[str, int]:
        counts = np.bincount(np.asarray(self.status), minlength=4)
        return {STATUS_NAMES[i]: int(c) for i, c in enumerate(counts)}


def _n_points(inputs) -> int:
    leaves = jax.tree_util.tree_leaves(inputs)
    if not leaves:
        raise ValueError("inputs must hold at least one array with a leading batch axis")
    n = int(np.shape(leaves[0])[0])
    for leaf in leaves:
        if np.shape(leaf)[0] != n:
            raise ValueError(
                f"all inputs need the same leading axis; got {np.shape(leaf)[0]} and {n}"
            )
    return n


def _slice(tree, lo, hi, pad_to=None):
    def cut(x):
        x = np.asarray(x)[lo:hi]
        if pad_to is not None and x.shape[0] < pad_to:
            reps = np.repeat(x[-1:], pad_to - x.shape[0], axis=0)
            x = np.concatenate([x, reps], axis=0)
        return x

    return jax.tree_util.tree_map(cut, tree)


def _fingerprint(inputs, extra: str) -> str:
    h = hashlib.sha256(extra.encode())
    arrays, static = eqx.partition(inputs, eqx.is_array_like)
    h.update(repr(jax.tree_util.tree_structure(arrays)).encode() + repr(static).encode())
    for leaf in jax.tree_util.tree_leaves(arrays):
        arr = np.ascontiguousarray(np.asarray(leaf))
        h.update(str(arr.dtype).encode() + str(arr.shape).encode())
        h.update(arr.tobytes())
    return h.hexdigest()[:16]


def _finite_mask(out, n) -> np.ndarray:
    ok = np.ones(n, dtype=bool)
    for leaf in jax.tree_util.tree_leaves(out):
        arr = np.asarray(leaf)
        if np.issubdtype(arr.dtype, np.inexact):
            ok &= np.all(np.isfinite(arr.reshape(n, -1)), axis=1)
    return ok


class _Progress:
    def __init__(self, total: int, label: str, enabled: bool):
        self.total, self.label, self.enabled = total, label, enabled
        self.t0 = time.perf_counter()

    def update(self, done: int, note: str = "") -> None:
        if not self.enabled:
            return
        width = 30
        fill = int(width * done / max(self.total, 1))
        elapsed = time.perf_counter() - self.t0
        bar = "#" * fill + "-" * (width - fill)
        sys.stderr.write(
            f"\r{self.label} [{bar}] {done}/{self.total} points, {elapsed:6.1f} s {note}"
        )
        if done >= self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def _store(checkpoint_dir: Path | None, index: int, out, status, carry=None) -> None:
    if checkpoint_dir is None:
        return
    leaves = jax.tree_util.tree_leaves(out)
    arrays = {f"leaf{i}": np.asarray(x) for i, x in enumerate(leaves)}
    arrays["status"] = np.asarray(status)
    if carry is not None:
        for i, x in enumerate(jax.tree_util.tree_leaves(carry)):
            arrays[f"carry{i}"] = np.asarray(x)
    tmp = checkpoint_dir / f"chunk_{index:05d}.tmp.npz"
    np.savez(tmp, **arrays)
    tmp.replace(
        checkpoint_dir / f"chunk_{index:05d}.npz"
    )  # atomic: a half-written chunk never counts


def _load(checkpoint_dir: Path | None, index: int, out_treedef, carry_treedef=None):
    if checkpoint_dir is None:
        return None
    path = checkpoint_dir / f"chunk_{index:05d}.npz"
    if not path.exists():
        return None
    with np.load(path) as data:
        n_leaves = out_treedef.num_leaves
        if sum(k.startswith("leaf") for k in data.files) != n_leaves:
            # written by a version of jaxgear with other outputs: recomputed, never misread
            return None
        out = jax.tree_util.tree_unflatten(out_treedef, [data[f"leaf{i}"] for i in range(n_leaves)])
        status = data["status"]
        carry = None
        if carry_treedef is not None:
            carry = jax.tree_util.tree_unflatten(
                carry_treedef, [data[f"carry{i}"] for i in range(carry_treedef.num_leaves)]
            )
    return out, status, carry


def _prepare_dir(checkpoint_dir, fingerprint: str) -> Path | None:
    if checkpoint_dir is None:
        return None
    d = Path(checkpoint_dir)
    d.mkdir(parents=True, exist_ok=True)
    manifest = d / "manifest.json"
    if manifest.exists():
        old = json.loads(manifest.read_text()).get("fingerprint")
        if old != fingerprint:
            # Different inputs: finished chunks of another sweep must not be reused.
            for f in d.glob("chunk_*.npz"):
                f.unlink()
    manifest.write_text(json.dumps({"fingerprint": fingerprint}))
    return d


def _batch_sharding(devices, chunk_size: int):
    devices = list(devices) if devices is not None else jax.devices()
    if len(devices) <= 1:
        return None, 1
    if chunk_size % len(devices):
        raise ValueError(
            f"chunk_size = {chunk_size} must be a multiple of the number of devices ({len(devices)})"
        )
    mesh = Mesh(np.asarray(devices), ("batch",))
    return NamedSharding(mesh, PartitionSpec("batch")), len(devices)


def _status_from(out, n, converged_key: str | None):
    status = np.full(n, OK, dtype=np.int32)
    if converged_key is not None and isinstance(out, dict) and converged_key in out:
        status[~np.asarray(out[converged_key]).astype(bool).reshape(n)] = NOT_CONVERGED
    status[~_finite_mask(out, n)] = NON_FINITE
    return status


def _nan_like(shape_dtype_tree, n):
    def fill(sd):
        if np.issubdtype(sd.dtype, np.inexact):
            return np.full((n, *sd.shape[1:]), np.nan, dtype=sd.dtype)
        return np.zeros((n, *sd.shape[1:]), dtype=sd.dtype)

    return jax.tree_util.tree_map(fill, shape_dtype_tree)


@functools.lru_cache(maxsize=32)
def _batched_with_args(point_fn, sequential: bool = False):
    """One compiled-function cache per point function, shared by every sweep that uses it."""
    if sequential:
        return eqx.filter_jit(lambda xs, args: jax.lax.map(lambda x: point_fn(x, args), xs))
    return eqx.filter_jit(eqx.filter_vmap(point_fn, in_axes=(0, None)))


@functools.lru_cache(maxsize=32)
def _scan_with_args(step_fn):
    @eqx.filter_jit
    def scan_chunk(carry, xs, args):
        return jax.lax.scan(lambda c, x: step_fn(c, x, args), carry, xs)

    return scan_chunk


def run_points(
    point_fn: Callable[..., Any],
    inputs: Any,
    *,
    args: Any = None,
    chunk_size: int | None = None,
    checkpoint_dir: str | Path | None = None,
    progress: bool = False,
    devices=None,
    converged_key: str | None = "converged",
    label: str = "sweep",
    sequential: bool = False,
) -> SweepOutput:
    """Evaluate ``point_fn`` (one point → pytree of arrays) on every row of ``inputs``.

    Args:
        point_fn: pure, jit-able function of one point's inputs (and of ``args`` if given:
            ``point_fn(point, args)``). If it returns a dict with a boolean ``converged_key`` entry,
            points where it is False get status NOT_CONVERGED.
        inputs: pytree of arrays with leading axis N.
        args: pytree shared by all points (not batched; non-array leaves are static). Give it, with a
            module-level ``point_fn``, so later sweeps reuse the compiled chunk.
        chunk_size: points per chunk (default: all in one chunk, rounded up to the device count).
        checkpoint_dir: where finished chunks go; a rerun with the same inputs resumes from them.
        progress: print a progress bar on stderr.
        devices: devices to shard each chunk over (default all of ``jax.devices()``).
        label: progress-bar label (also part of the checkpoint fingerprint).
        sequential: evaluate the points of a chunk one after the other (``lax.map``) instead of
            vmapped. For point functions with data-dependent fallbacks (``lax.cond``): under vmap a
            cond becomes a select that runs every branch for every point; on a CPU the vmap gains
            nothing to pay for that.
    """
    n = _n_points(inputs)
    n_dev = len(list(devices) if devices is not None else jax.devices())
    chunk = chunk_size or n
    chunk = -(-chunk // n_dev) * n_dev
    sharding, _ = _batch_sharding(devices, chunk)
    fingerprint = _fingerprint((inputs, args), f"{label}:{chunk}")
    ckpt = _prepare_dir(checkpoint_dir, fingerprint)
    if args is None:
        mapped = functools.partial(jax.lax.map, point_fn) if sequential else jax.vmap(point_fn)
        batched = jax.jit(mapped)
    else:
        compiled = _batched_with_args(point_fn, sequential)
        batched = lambda xs: compiled(xs, args)
    example = _slice(inputs, 0, 1, pad_to=chunk)
    out_struct = eqx.filter_eval_shape(batched, example)
    treedef = jax.tree_util.tree_structure(out_struct)
    pieces, statuses, messages = [], [], []
    bar = _Progress(n, label, progress)
    for index, lo in enumerate(range(0, n, chunk)):
        hi = min(lo + chunk, n)
        loaded = _load(ckpt, index, treedef)
        if loaded is not None:
            out, status, _ = loaded
        else:
            xs = _slice(inputs, lo, hi, pad_to=chunk)
            if sharding is not None:
                xs = jax.device_put(xs, sharding)
            try:
                out = jax.tree_util.tree_map(np.asarray, jax.block_until_ready(batched(xs)))
                out = _slice(out, 0, hi - lo)
                status = _status_from(out, hi - lo, converged_key)
            except Exception as err:  # noqa: BLE001 - keep every good point, report this chunk
                messages.append(f"points {lo}-{hi - 1}: {type(err).__name__}: {err}")
                out = _nan_like(out_struct, hi - lo)
                status = np.full(hi - lo, FAILED, dtype=np.int32)
            else:
                _store(ckpt, index, out, status)
        pieces.append(out)
        statuses.append(np.asarray(status))
        bar.update(hi, f"({int(np.sum(np.concatenate(statuses) != OK))} not ok)")
    outputs = jax.tree_util.tree_map(lambda *xs: np.concatenate(xs, axis=0), *pieces)
    return SweepOutput(outputs=outputs, status=np.concatenate(statuses), messages=tuple(messages))


def run_continuation(
    step_fn: Callable[..., tuple[Any, Any]],
    carry0: Any,
    inputs: Any,
    *,
    args: Any = None,
    chunk_size: int | None = None,
    checkpoint_dir: str | Path | None = None,
    progress: bool = False,
    converged_key: str | None = "converged",
    label: str = "continuation",
) -> SweepOutput:
    """Sequential sweep: ``lax.scan(step_fn, carry, inputs)`` cut into chunks, with the carry stored
    with each finished chunk so an interrupted sweep resumes where it stopped. A chunk that raises
    ends the sweep there: the points before it are kept, the rest are marked FAILED.

    With ``args`` the step is ``step_fn(carry, point, args)`` (see ``run_points``)."""
    n = _n_points(inputs)
    chunk = chunk_size or n
    fingerprint = _fingerprint((carry0, inputs, args), f"{label}:{chunk}")
    ckpt = _prepare_dir(checkpoint_dir, fingerprint)

    if args is None:

        @jax.jit
        def scan_chunk(carry, xs):
            return jax.lax.scan(step_fn, carry, xs)

    else:
        compiled = _scan_with_args(step_fn)
        scan_chunk = lambda carry, xs: compiled(carry, xs, args)

    carry = carry0
    carry_treedef = jax.tree_util.tree_structure(carry0)
    first = _slice(inputs, 0, min(chunk, n), pad_to=chunk)
    out_struct = eqx.filter_eval_shape(scan_chunk, carry0, first)[1]
    treedef = jax.tree_util.tree_structure(out_struct)
    pieces, statuses, messages = [], [], []
    bar = _Progress(n, label, progress)
    broken = False
    for index, lo in enumerate(range(0, n, chunk)):
        hi = min(lo + chunk, n)
        loaded = None if broken else _load(ckpt, index, treedef, carry_treedef)
        if broken:
            struct = eqx.filter_eval_shape(scan_chunk, carry0, _slice(inputs, lo, hi))[1]
            out, status = _nan_like(struct, hi - lo), np.full(hi - lo, FAILED, dtype=np.int32)
        elif loaded is not None:
            out, status, carry = loaded
        else:
            try:
                # The last chunk is padded by repeating its final point (one compiled shape; the
                # repeats leave the carry at that point's converged state) and the extra rows dropped.
                xs = _slice(inputs, lo, hi, pad_to=chunk)
                carry, out = jax.block_until_ready(scan_chunk(carry, xs))
                out = _slice(jax.tree_util.tree_map(np.asarray, out), 0, hi - lo)
                status = _status_from(out, hi - lo, converged_key)
                _store(ckpt, index, out, status, carry)
            except Exception as err:  # noqa: BLE001
                messages.append(f"points {lo}-{hi - 1}: {type(err).__name__}: {err}")
                struct = eqx.filter_eval_shape(scan_chunk, carry0, _slice(inputs, lo, hi))[1]
                out, status = _nan_like(struct, hi - lo), np.full(hi - lo, FAILED, dtype=np.int32)
                broken = True
        pieces.append(out)
        statuses.append(np.asarray(status))
        bar.update(hi)
    outputs = jax.tree_util.tree_map(lambda *xs: np.concatenate(xs, axis=0), *pieces)
    return SweepOutput(outputs=outputs, status=np.concatenate(statuses), messages=tuple(messages))


def stack_inputs(**arrays) -> dict[str, jnp.ndarray]:
    """Broadcast named per-point inputs to a common leading length (scalars are repeated)."""
    n = max((np.size(v) for v in arrays.values()), default=1)
    out = {}
    for name, v in arrays.items():
        v = np.asarray(v, dtype=float)
        if v.ndim == 0:
            v = np.full(n, float(v))
        if v.shape[0] != n:
            raise ValueError(f"{name} has {v.shape[0]} points; expected 1 or {n}")
        out[name] = v
    return out
