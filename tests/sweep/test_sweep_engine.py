"""The sweep engine: chunks equal one batch equal a loop; statuses; failures keep good points;
checkpoint/resume never recomputes finished chunks; two-device sharding equals one device."""

import json
import os
import subprocess
import sys
import textwrap

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxgear.sweep import engine as sweep_engine
from jaxgear.sweep.engine import (
    FAILED,
    NON_FINITE,
    NOT_CONVERGED,
    OK,
    run_continuation,
    run_points,
)


def point(inp):
    x = inp["x"]
    y = jnp.sin(x) * inp["a"]
    return {"y": y, "vec": jnp.stack([x, x**2]), "converged": x < 8.5}


def test_chunks_equal_loop_and_status():
    xs = np.linspace(0.0, 10.0, 23)
    inputs = {"x": xs, "a": np.full(23, 2.0)}
    res = run_points(point, inputs, chunk_size=5)
    assert res.outputs["y"].shape == (23,)
    loop = np.array([float(point({"x": jnp.asarray(x), "a": 2.0})["y"]) for x in xs])
    np.testing.assert_allclose(res.outputs["y"], loop, rtol=1e-15)
    np.testing.assert_array_equal(res.status, np.where(xs < 8.5, OK, NOT_CONVERGED))
    assert res.summary()["not converged"] == int(np.sum(xs >= 8.5))


def _point_with_args(inp, args):
    # a data-dependent branch, as the EHL solves' fallbacks
    y = jax.lax.cond(inp["x"] > args, lambda: jnp.sin(inp["x"]), lambda: -inp["x"])
    return {"y": y, "converged": inp["x"] < 8.5}


@pytest.mark.parametrize("with_args", [False, True])
def test_sequential_chunks_equal_vmapped(with_args):
    xs = np.linspace(0.0, 10.0, 11)
    if with_args:
        kw = dict(args=jnp.asarray(4.0))
        fn = _point_with_args
    else:
        kw = {}
        fn = point
        xs_in = {"x": xs, "a": np.full(11, 2.0)}
    inputs = {"x": xs} if with_args else xs_in
    seq = run_points(fn, inputs, chunk_size=4, sequential=True, **kw)
    par = run_points(fn, inputs, chunk_size=4, **kw)
    np.testing.assert_allclose(seq.outputs["y"], par.outputs["y"], rtol=1e-15)
    np.testing.assert_array_equal(seq.status, par.status)


def test_non_finite_points_are_flagged_and_others_kept():
    def fn(inp):
        return {"y": jnp.log(inp["x"])}  # NaN for x < 0

    xs = np.array([1.0, -1.0, 2.0, 3.0])
    res = run_points(fn, {"x": xs}, chunk_size=2, converged_key=None)
    np.testing.assert_array_equal(res.status, [OK, NON_FINITE, OK, OK])
    np.testing.assert_allclose(res.outputs["y"][[0, 2, 3]], np.log(xs[[0, 2, 3]]))


def test_raising_chunk_is_marked_failed_and_others_kept():
    def fn(inp):
        x = eqx.error_if(inp["x"], inp["x"] > 100.0, "x too large")
        return {"y": 2 * x}

    xs = np.array([1.0, 2.0, 300.0, 4.0, 5.0, 6.0])
    res = run_points(fn, {"x": xs}, chunk_size=2, converged_key=None)
    np.testing.assert_array_equal(res.status, [OK, OK, FAILED, FAILED, OK, OK])
    np.testing.assert_allclose(res.outputs["y"][[0, 1, 4, 5]], 2 * xs[[0, 1, 4, 5]])
    assert np.all(np.isnan(res.outputs["y"][2:4]))
    assert len(res.messages) == 1 and "x too large" in res.messages[0]


def test_resume_reuses_finished_chunks(tmp_path):
    xs = np.arange(10.0)
    first = run_points(
        lambda p: {"y": p["x"] + 1.0},
        {"x": xs},
        chunk_size=3,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    files = sorted(p.name for p in tmp_path.glob("chunk_*.npz"))
    assert files == [f"chunk_{i:05d}.npz" for i in range(4)]
    # "Interrupt": lose chunk 2. A rerun with a different function shows which chunks were
    # recomputed: only chunk 2 (points 6-8) carries the new function's values.
    (tmp_path / "chunk_00002.npz").unlink()
    second = run_points(
        lambda p: {"y": p["x"] + 1000.0},
        {"x": xs},
        chunk_size=3,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    expected = first.outputs["y"].copy()
    expected[6:9] = xs[6:9] + 1000.0
    np.testing.assert_array_equal(second.outputs["y"], expected)
    # Different inputs invalidate the checkpoint: nothing stale is reused.
    third = run_points(
        lambda p: {"y": p["x"] + 1000.0},
        {"x": xs + 0.5},
        chunk_size=3,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    np.testing.assert_array_equal(third.outputs["y"], xs + 1000.5)
    assert json.loads((tmp_path / "manifest.json").read_text())["fingerprint"]


def test_continuation_carries_state_and_resumes(tmp_path):
    def step(carry, inp):
        new = carry + inp["x"]
        return new, {"cum": new}

    xs = np.arange(1.0, 11.0)
    res = run_continuation(
        step, jnp.asarray(0.0), {"x": xs}, chunk_size=4, checkpoint_dir=tmp_path, converged_key=None
    )
    np.testing.assert_allclose(res.outputs["cum"], np.cumsum(xs))
    (tmp_path / "chunk_00002.npz").unlink()
    again = run_continuation(
        step, jnp.asarray(0.0), {"x": xs}, chunk_size=4, checkpoint_dir=tmp_path, converged_key=None
    )
    np.testing.assert_allclose(again.outputs["cum"], np.cumsum(xs))


def _interrupt_after(monkeypatch, points_done):
    """Ctrl-C between chunks, once ``points_done`` points have finished (the progress update runs
    after a chunk is stored, so this is an interruption at the worst moment that loses nothing)."""

    def update(self, done, note=""):
        if done >= points_done:
            raise KeyboardInterrupt

    monkeypatch.setattr(sweep_engine._Progress, "update", update)


def test_interrupted_sweep_keeps_finished_chunks(tmp_path, monkeypatch):
    xs = np.arange(10.0)
    with monkeypatch.context() as patch:
        _interrupt_after(patch, 6)
        with pytest.raises(KeyboardInterrupt):
            run_points(
                lambda p: {"y": p["x"] + 1.0},
                {"x": xs},
                chunk_size=3,
                checkpoint_dir=tmp_path,
                converged_key=None,
            )
    assert sorted(p.name for p in tmp_path.glob("chunk_*.npz")) == [
        "chunk_00000.npz",
        "chunk_00001.npz",
    ]
    # The rerun (a different function shows what was recomputed) keeps the 6 finished points and
    # computes only the rest.
    again = run_points(
        lambda p: {"y": p["x"] + 1000.0},
        {"x": xs},
        chunk_size=3,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    np.testing.assert_array_equal(again.outputs["y"], np.where(xs < 6, xs + 1.0, xs + 1000.0))
    np.testing.assert_array_equal(again.status, OK)


def test_continuation_failing_chunk_keeps_earlier_points_and_resumes(tmp_path):
    def step(carry, inp):
        new = eqx.error_if(carry + inp["x"], inp["x"] == 7.0, "point 7 fails")
        return new, {"cum": new}

    xs = np.arange(1.0, 11.0)
    res = run_continuation(
        step, jnp.asarray(0.0), {"x": xs}, chunk_size=3, checkpoint_dir=tmp_path, converged_key=None
    )
    # Points 1-6 (two chunks) finished and are kept; the chunk holding point 7 raised, and the
    # march stops there: the rest is marked FAILED rather than started from a wrong carry.
    np.testing.assert_allclose(res.outputs["cum"][:6], np.cumsum(xs)[:6])
    np.testing.assert_array_equal(res.status, [OK] * 6 + [FAILED] * 4)
    assert np.all(np.isnan(res.outputs["cum"][6:]))
    assert len(res.messages) == 1 and "point 7 fails" in res.messages[0]

    # Fixed, the rerun loads the two finished chunks and resumes from the carry stored with the
    # second: a step that adds 1000 more shows which points were recomputed, and from what state.
    def fixed(carry, inp):
        new = carry + inp["x"] + 1000.0
        return new, {"cum": new}

    again = run_continuation(
        fixed,
        jnp.asarray(0.0),
        {"x": xs},
        chunk_size=3,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    expected = np.cumsum(xs)
    expected[6:] = expected[5] + np.cumsum(xs[6:] + 1000.0)
    np.testing.assert_allclose(again.outputs["cum"], expected)
    np.testing.assert_array_equal(again.status, OK)


TRACES = []


def scaled(inp, args):
    TRACES.append(1)  # runs once per trace, not per call
    return {"y": inp["x"] * args["a"]}


def scaled_step(carry, inp, args):
    TRACES.append(1)
    new = carry + inp["x"] * args["a"]
    return new, {"cum": new}


def test_shared_args_reuse_the_compiled_chunk_and_enter_the_fingerprint(tmp_path):
    xs = np.arange(6.0)
    TRACES.clear()
    one = run_points(
        scaled, {"x": xs}, args={"a": jnp.asarray(2.0)}, chunk_size=3, converged_key=None
    )
    two = run_points(
        scaled, {"x": xs}, args={"a": jnp.asarray(3.0)}, chunk_size=3, converged_key=None
    )
    np.testing.assert_array_equal(one.outputs["y"], 2 * xs)
    np.testing.assert_array_equal(two.outputs["y"], 3 * xs)
    assert len(TRACES) == 1  # the second sweep reused the first one's compiled chunk
    TRACES.clear()
    cum = lambda a: run_continuation(
        scaled_step,
        jnp.zeros(()),
        {"x": xs},
        args={"a": jnp.asarray(a)},
        chunk_size=4,
        checkpoint_dir=tmp_path,
        converged_key=None,
    )
    np.testing.assert_allclose(cum(2.0).outputs["cum"], np.cumsum(2 * xs))
    # Same points, other shared inputs, same checkpoint directory: nothing stale is reused.
    np.testing.assert_allclose(cum(5.0).outputs["cum"], np.cumsum(5 * xs))
    assert len(TRACES) == 1


def test_sharded_over_two_host_devices_equals_single_device(tmp_path):
    # A fresh process is needed: the device count is fixed when JAX starts.
    script = textwrap.dedent(
        """
        import jax, numpy as np, jax.numpy as jnp
        jax.config.update("jax_enable_x64", True)
        from jaxgear.sweep.engine import run_points
        assert len(jax.devices()) == 2, jax.devices()
        f = lambda p: {"y": jnp.sin(p["x"]) * jnp.exp(-p["x"])}
        xs = np.linspace(0.0, 5.0, 13)
        two = run_points(f, {"x": xs}, chunk_size=4, converged_key=None)
        one = run_points(f, {"x": xs}, chunk_size=4, devices=jax.devices()[:1], converged_key=None)
        np.save(r"%s", np.stack([two.outputs["y"], one.outputs["y"]]))
        """
        % (tmp_path / "out.npy")
    )
    env = {
        **os.environ,
        "XLA_FLAGS": "--xla_force_host_platform_device_count=2",
        "JAX_PLATFORMS": "cpu",
    }
    proc = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    two, one = np.load(tmp_path / "out.npy")
    np.testing.assert_array_equal(two, one)
    np.testing.assert_allclose(
        two, np.sin(np.linspace(0, 5, 13)) * np.exp(-np.linspace(0, 5, 13)), rtol=1e-14
    )


def test_bad_inputs():
    with pytest.raises(ValueError, match="same leading axis"):
        run_points(point, {"x": np.zeros(3), "a": np.zeros(4)})
