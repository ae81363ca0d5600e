"""jg.sweep on the physics: parallel equals a loop of simulate, continuation equals parallel,
resume after interruption, two-device sharding equals one device, bad input. Quasi-static rung for
cost; the engine itself is tested in test_sweep_engine.py."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from helpers import ROOT

import jaxgear as jg
from jaxgear.fidelity import Fidelity
from jaxgear.sweep import sweep
from jaxgear.tribodynamics import simulate

FID = Fidelity(dynamics="quasi_static", friction="regression")


@pytest.fixture(scope="module")
def base():
    pair = jg.presets.li2015_pair()
    return pair, jg.presets.mil_l_23699(), jg.presets.ground(), jg.OperatingPoint(700.0, 1000.0)


def test_parallel_equals_loop_and_continuation(base):
    pair, lub, surf, op = base
    speeds = np.array([600.0, 1700.0, 2900.0, 4100.0])
    res = sweep(pair, lub, surf, op, speeds_rpm=speeds, fidelity=FID, chunk_size=3)
    loop = [
        float(simulate(pair, lub, surf, jg.OperatingPoint(700.0, s), FID).power_loss)
        for s in speeds
    ]
    np.testing.assert_allclose(res.power_loss, loop, rtol=1e-12)
    assert np.all(res.converged)
    cont = sweep(pair, lub, surf, op, speeds_rpm=speeds, fidelity=FID, mode="continuation")
    np.testing.assert_allclose(cont.power_loss, res.power_loss, rtol=1e-12)


def test_other_inputs_and_csv(base, tmp_path):
    pair, lub, surf, op = base
    res = sweep(
        pair,
        lub,
        surf,
        op,
        speeds_rpm=2000.0,
        torque=[500.0, 700.0, 1500.0],
        inlet_temperature=333.15,
        roughness_scale=[1.0, 1.0, 0.5],
        fidelity=FID,
    )
    # More torque, more loss; efficiency only slightly changed (REFERENCE §7 R7 trend).
    assert res.power_loss[2] > res.power_loss[1] > res.power_loss[0]
    assert abs(res.efficiency[2] - res.efficiency[1]) < 0.005
    path = res.to_csv(tmp_path / "s.csv")
    lines = path.read_text().splitlines()
    assert lines[0].startswith("speed_rpm,torque,inlet_temperature_C,roughness_scale")
    assert len(lines) == 4 and lines[1].endswith(",ok")


def test_resume_after_interruption(base, tmp_path):
    pair, lub, surf, op = base
    speeds = np.arange(500.0, 1001.0, 100.0)
    first = sweep(
        pair, lub, surf, op, speeds_rpm=speeds, fidelity=FID, chunk_size=2, checkpoint_dir=tmp_path
    )
    chunks = sorted(tmp_path.glob("chunk_*.npz"))
    assert len(chunks) == 3
    chunks[1].unlink()  # the "interrupted" run lost its second chunk
    again = sweep(
        pair, lub, surf, op, speeds_rpm=speeds, fidelity=FID, chunk_size=2, checkpoint_dir=tmp_path
    )
    np.testing.assert_array_equal(again.power_loss, first.power_loss)
    assert len(sorted(tmp_path.glob("chunk_*.npz"))) == 3


def test_checkpoint_belongs_to_its_base_point(base, tmp_path):
    # Same speeds, same checkpoint directory, another torque: the finished chunks of the first sweep
    # must not be taken for the second (they once were: the fingerprint covered the speeds only).
    pair, lub, surf, _ = base
    speeds = np.array([600.0, 1700.0, 2900.0])
    loss = {
        torque: sweep(
            pair,
            lub,
            surf,
            jg.OperatingPoint(torque, 1000.0),
            speeds_rpm=speeds,
            fidelity=FID,
            chunk_size=3,
            checkpoint_dir=tmp_path,
        ).power_loss
        for torque in (700.0, 1500.0)
    }
    fresh = sweep(
        pair, lub, surf, jg.OperatingPoint(1500.0, 1000.0), speeds_rpm=speeds, fidelity=FID
    )
    np.testing.assert_allclose(loss[1500.0], fresh.power_loss, rtol=1e-12)
    assert np.all(loss[1500.0] > 1.5 * loss[700.0])


def test_per_position_outputs_match_simulate(base):
    pair, lub, surf, op = base
    res = sweep(pair, lub, surf, op, speeds_rpm=[600.0, 1700.0, 2900.0], fidelity=FID, chunk_size=3)
    one = simulate(pair, lub, surf, jg.OperatingPoint(700.0, 1700.0), FID)
    for name in ("power_loss_position", "tooth_force", "surface_velocity", "hertz_pressure"):
        np.testing.assert_allclose(getattr(res, name)[1], getattr(one, name), rtol=1e-12)


def test_sharded_sweep_equals_single_device(tmp_path):
    script = textwrap.dedent(
        """
        import jax, numpy as np
        jax.config.update("jax_enable_x64", True)
        import jaxgear as jg
        from jaxgear.fidelity import Fidelity
        from jaxgear.sweep import sweep
        assert len(jax.devices()) == 2
        fid = Fidelity(dynamics="quasi_static", friction="regression")
        args = (jg.presets.li2015_pair(), jg.presets.mil_l_23699(), jg.presets.ground(),
                jg.OperatingPoint(700.0, 1000.0))
        speeds = np.array([700.0, 1400.0, 2100.0, 2800.0, 3500.0])
        two = sweep(*args, speeds_rpm=speeds, fidelity=fid, chunk_size=4)
        one = sweep(*args, speeds_rpm=speeds, fidelity=fid, chunk_size=4,
                    devices=jax.devices()[:1])
        np.save(r"%s", np.stack([two.power_loss, one.power_loss]))
        """
        % (tmp_path / "out.npy")
    )
    env = {
        **os.environ,
        "XLA_FLAGS": "--xla_force_host_platform_device_count=2",
        "JAX_PLATFORMS": "cpu",
    }
    proc = subprocess.run(
        [sys.executable, "-c", script],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    two, one = np.load(tmp_path / "out.npy")
    np.testing.assert_allclose(two, one, rtol=1e-12)


def test_bad_sweep_input(base):
    pair, lub, surf, op = base
    with pytest.raises(ValueError, match="speeds_rpm = .* is out of range"):
        sweep(pair, lub, surf, op, speeds_rpm=[1000.0, -5.0], fidelity=FID)
    with pytest.raises(ValueError, match="cannot sweep"):
        sweep(pair, lub, surf, op, speeds_rpm=[1000.0], module=[3e-3], fidelity=FID)
    with pytest.raises(ValueError, match="mode = 'serial'"):
        sweep(pair, lub, surf, op, speeds_rpm=[1000.0], mode="serial", fidelity=FID)
    with pytest.raises(ValueError, match="torque has 2 points"):
        sweep(pair, lub, surf, op, speeds_rpm=[1.0e3, 2e3, 3e3], torque=[1.0, 2.0], fidelity=FID)


def test_second_pass_chains_keep_neighbours_in_order():
    # The second pass runs its chains side by side: in a continuation sweep a run of neighbouring
    # flagged points is one chain (each continues from the one before, in order), so a chain must
    # never be split or reordered; in a parallel sweep every point is its own chain. The longest
    # chain comes first (it sets the second pass's wall time).
    import importlib

    api = importlib.import_module("jaxgear.sweep.api")
    idx = np.asarray([3, 4, 5, 9, 11, 12, 20])
    assert api._chains(idx, continuation=True) == [[3, 4, 5], [11, 12], [9], [20]]
    assert sorted(api._chains(idx, continuation=False)) == [[int(i)] for i in idx]
    assert api._chains(np.asarray([], dtype=int), continuation=True) == []
