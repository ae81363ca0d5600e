"""Back-flank contact: where rattling teeth cross the backlash the back flanks carry the mesh force.

``gear.mesh.back_flank_mesh`` places their contacts from the mirror image of the drive mesh; the
checks here build the teeth another way, as involute curves through the contact points in the
plane of the gears, and measure the tooth thickness between the two flanks. The back flanks'
loss (``tribodynamics.second_pass.back_flank_power``) is checked against the drive flanks' quasi-static loss
at the same load, which the mirror symmetry makes equal over a cycle.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxgear as jg
from jaxgear.fidelity import Fidelity
from jaxgear.gear.geometry import gear_geometry
from jaxgear.gear.mesh import back_flank_mesh, mesh_cycle
from jaxgear.tribodynamics.fixed_point import cycle_contacts
from jaxgear.tribodynamics.second_pass import back_flank_power


def _involute(rb, beta, t, hand):
    """Involute of the base circle rb from polar angle beta, roll t; hand +1: its polar angle
    grows with the radius, −1: falls."""
    a = beta + hand * t
    return rb * np.array([np.cos(a) + hand * t * np.sin(a), np.sin(a) - hand * t * np.cos(a)])


def _flank_through(q, rb, hand):
    """(beta, roll at q) of the involute of ``hand`` through the point q."""
    t = math.sqrt(q @ q / rb**2 - 1.0)
    return math.atan2(q[1], q[0]) - hand * (t - math.atan(t)), t


def _polar_at(rb, beta, hand, r):
    t = math.sqrt(r**2 / rb**2 - 1.0)
    p = _involute(rb, beta, t, hand)
    return math.atan2(p[1], p[0])


PAIRS = {
    "paper": jg.presets.li2015_pair(),
    "shifted 23/47": jg.GearPair(
        teeth=(23, 47),
        module=4e-3,
        pressure_angle=math.radians(25.0),
        face_width=0.03,
        profile_shift=(0.3, -0.1),
    ),
}


@pytest.mark.parametrize("name", list(PAIRS))
def test_back_contacts_stand_a_tooth_thickness_from_the_drive_contacts(name):
    # Gear 1 at O1 = 0, gear 2 above it. LOA1 touches gear 1's base circle at T1 (right of the
    # line of centres) and runs towards gear 2's; LOA2 is its mirror image. Through the drive
    # contact (slot 0 of the drive mesh at each phase) passes the leading, left flank of a tooth
    # of gear 1 (its polar angle falls with the radius); through each back contact in the path, a
    # right flank. Each involute's normal at its contact must be its line of action (which checks
    # the hands), and between the left flank and the right flank of the same tooth the angle at
    # the reference radius is the tooth's thickness s/r = m (π/2 + 2 x1 tan α)/r_ref, modulo the
    # angular pitch. The clearance is not in the geometry (tooth thickness nominal), so the
    # tolerance is round-off: measured 1e-15 rad.
    pair = PAIRS[name]
    geo = gear_geometry(pair)
    rb, aw = float(geo.base_radius[0]), float(geo.operating_pressure_angle)
    r_ref, z1 = float(geo.reference_pitch_radius[0]), pair.teeth[0]
    alpha, x1 = float(pair.pressure_angle), float(pair.profile_shift[0])
    thickness = float(pair.module) * (math.pi / 2 + 2 * x1 * math.tan(alpha)) / r_ref
    pitch = 2 * math.pi / z1
    t1, d1 = rb * np.array([math.sin(aw), math.cos(aw)]), np.array([-math.cos(aw), math.sin(aw)])
    t2, d2 = rb * np.array([-math.sin(aw), math.cos(aw)]), np.array([math.cos(aw), math.sin(aw)])
    drive = mesh_cycle(pair, 500.0, 16)
    back = back_flank_mesh(pair, 500.0, 16)
    checked = 0
    for i in range(16):
        q = t1 + float(drive.contact_position[i, 0]) * d1
        beta_d, t_d = _flank_through(q, rb, -1)
        tangent = _involute(rb, beta_d, t_d + 1e-4, -1) - _involute(rb, beta_d, t_d - 1e-4, -1)
        assert abs(tangent @ d1) < 1e-6 * np.linalg.norm(tangent)  # the normal is LOA1
        left = _polar_at(rb, beta_d, -1, r_ref)
        for slot in range(2):
            if float(back.in_contact[i, slot]) < 1.0:
                continue
            q2 = t2 + float(back.contact_position[i, slot]) * d2
            beta_b, t_b = _flank_through(q2, rb, +1)
            tangent = _involute(rb, beta_b, t_b + 1e-4, +1) - _involute(rb, beta_b, t_b - 1e-4, +1)
            assert abs(tangent @ d2) < 1e-6 * np.linalg.norm(tangent)  # the normal is LOA2
            right = _polar_at(rb, beta_b, +1, r_ref)
            gap = (left - right) % pitch
            assert gap == pytest.approx(thickness, abs=1e-12), (i, slot)
            checked += 1
    assert checked >= 16  # at least one back contact at every phase (contact ratio > 1)


def _static_losses(pair, m):
    """(drive, back): constant-μ loss of the quasi-static cycle on M = m positions, and of the
    back flanks carrying the static mesh force at every position."""
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    fid = Fidelity(dynamics="quasi_static", friction="constant", n_positions=m)
    op = jg.OperatingPoint(torque=700.0, speed_rpm=2000.0)
    drive = jg.simulate(pair, lub, surf, op, fid)
    mesh = mesh_cycle(pair, op.torque, m)

    def contacts(w, u, mm):
        return cycle_contacts(pair, lub, surf, op, fid, mm, w, u)[0]

    force = -jnp.full((1, m), float(mesh.total_load))
    sliding, rolling = back_flank_power(pair, op, fid, mesh, force, contacts)
    assert float(jnp.max(jnp.abs(rolling))) == 0.0  # the constant-μ rung has no rolling loss
    # none where the mesh force is positive (drive contact) or zero (separation)
    for other in (-force, jnp.zeros_like(force)):
        assert float(jnp.max(back_flank_power(pair, op, fid, mesh, other, contacts)[0])) == 0.0
    return float(drive.power_loss), float(jnp.mean(sliding))


def test_back_flank_loss_at_the_static_load_is_the_drive_flanks_of_the_paper_pair():
    # The mirror image of the back flanks' mesh is the drive mesh run backwards, and for the
    # paper's 1:1 pair of standard teeth the back contacts at phase τ mirror, about the pitch
    # point, the drive contacts at τ + 1/2: with the static force on the back flanks at every
    # position, an even M visits the drive cycle's values in another order (constant μ:
    # Φ = μ Σ W |us|). Equal to round-off (measured 4e-16).
    drive, back = _static_losses(jg.presets.li2015_pair_calibrated(), 64)
    assert back == pytest.approx(drive, rel=1e-12)


def test_back_flank_loss_at_the_static_load_converges_to_the_drive_flanks_of_any_pair():
    # For a 23/47 pair with profile shifts the back contacts visit the drive contacts' positions
    # at a shifted grid of phases (back_flank_phase: frac(c − τ), c M not an integer), so the two
    # cycle means are two equal-weight quadratures of one periodic integral. The load's rise and
    # fall at the path's ends are smooth steps (0.01 pb edges), so once M resolves them the two
    # agree fast: measured +2.0 / +0.42 / −0.002 % at M = 32 / 64 / 128. (Until 2026-11-29 this
    # pair's mesh was NaN at τ = 0, where its path starts on gear 2's tip, and the NaN position
    # dropped out of the drive loss: that read as a first-order gap, +6.5 / +2.6 / +1.1 %.)
    pair = PAIRS["shifted 23/47"]
    gaps = []
    for m in (32, 64, 128):
        drive, back = _static_losses(pair, m)
        gaps.append(back / drive - 1.0)
    assert abs(gaps[-1]) < 1e-3
    # Each doubling shrinks the gap at least 2× (measured 4.7× and 180×): a wrong phase or load
    # share would leave an O(1) offset that stalls.
    for coarse, fine in zip(gaps[:-1], gaps[1:]):
        assert abs(fine) < 0.5 * abs(coarse), gaps


def _back_dynamics(pair, m, back_flank="mirrored", speed_rpm=1000.0):
    from jaxgear.dynamics.model import DynamicsOptions, MeshInterface, build_dynamics

    op = jg.OperatingPoint(torque=700.0, speed_rpm=speed_rpm)
    mesh = mesh_cycle(pair, op.torque, m)
    options = DynamicsOptions(back_flank=back_flank)
    dyn = build_dynamics(pair, op, mesh, MeshInterface.zeros(m), options)
    return dyn, mesh, back_flank_mesh(pair, op.torque, m), options


def _mesh_force(dyn, tau, dte):
    """Fm (N) at τ for gear 1 turned by εd = ``dte`` along the line (no translations)."""
    q = jnp.zeros(jnp.shape(dte) + (6,)).at[..., 0].set(dte)
    return np.asarray(sum(dyn.flank_forces(tau, q)))


@pytest.mark.parametrize("name", list(PAIRS))
def test_back_flank_force_law_carries_the_back_mesh_static_load(name):
    # Statically loaded back flanks (torque reversed) stand at εd = −2ℓ − static TE of the back
    # mesh (back_flank_mesh: its own load sharing, at the mirrored contacts), so there the
    # dynamics' mesh force must be −W, as +W at the drive mesh's static TE. The dynamics reads
    # the back flanks' km and e from its drive tables' periodic spline at the mirrored phase
    # frac(c − τ), off the table's nodes: exact where km is smooth, with the spline's ringing
    # where a pair enters or leaves (the edges' steps), which falls with M. Measured (paper /
    # 23/47): median 2.8e-6 / 4.0e-6 of W at M = 64, 1e-10 at 128; max 0.15 / 0.07 at 64, 0.013 /
    # 0.0075 at 256. The single backlash function of the drive side ("same") is off by 37-40 % in
    # the median: the test tells the two apart.
    pair = PAIRS[name]
    gaps = {}
    for m in (64, 256):
        dyn, mesh, back, _ = _back_dynamics(pair, m)
        tau, w = mesh.mesh_fraction, float(mesh.total_load)
        drive = _mesh_force(dyn, tau, mesh.static_te) / w
        np.testing.assert_allclose(drive, 1.0, rtol=1e-12)  # the drive tables' own nodes
        gaps[m] = np.abs(_mesh_force(dyn, tau, -pair.backlash - back.static_te) / w + 1)
    assert np.median(gaps[64]) < 1e-4
    assert np.median(gaps[256]) < 1e-8
    assert gaps[64].max() < 0.2  # the spline's ringing at the edges' steps
    assert gaps[256].max() < 0.02  # falls with the grid (measured ≥ 7× from 64 to 256)
    same, mesh, back, _ = _back_dynamics(pair, 64, back_flank="same")
    old = _mesh_force(same, mesh.mesh_fraction, -pair.backlash - back.static_te)
    assert np.median(np.abs(old / float(mesh.total_load) + 1)) > 0.3


def test_reversed_torque_settles_on_the_back_flanks_static_te():
    # The whole dynamics under a reversed torque at 10 rpm (mesh frequency 8 Hz against a first
    # mode ~2.2 kHz: dynamic amplification ~1e-5) must settle on the back flanks: the relative
    # displacement along their line of action LOA2 at −2ℓ − the back mesh's static TE, the mesh
    # force −W on average, and the bearings carrying the back force along LOA2, at 2α_w to LOA1:
    # y1 = W cos 2α_w/ky1, x1 = −W sin 2α_w/kx1 and the opposite on gear 2 (closed forms of the
    # statics). Median errors measured ≤ 1.2e-6 of the scale; 10 of the 64 positions, next to the
    # back mesh's load steps, carry the spline's ringing (max 0.126; see the force-law test).
    import equinox as eqx

    from jaxgear.dynamics.model import LENGTH_SCALE
    from jaxgear.dynamics.response import postprocess
    from jaxgear.dynamics.shooting import periodic_orbit, static_guess

    pair = jg.presets.li2015_pair()
    dyn, mesh, back, options = _back_dynamics(pair, 64, speed_rpm=10.0)
    dyn = eqx.tree_at(lambda d: d.torque, dyn, -dyn.torque)
    w = static_guess(dyn)
    # start on the back flanks at τ = 0: the gears turned back through the clearance, the
    # bearings deflected the other way
    shift = (-pair.backlash - back.static_te[0] - mesh.static_te[0]) / LENGTH_SCALE
    w = w.at[0].add(0.5 * shift).at[3].add(-0.5 * shift).at[1].multiply(-1).at[4].multiply(-1)
    ws, stats, flow = jax.jit(lambda d, w0: periodic_orbit(d, w0, options, mesh.n_positions))(
        dyn, w
    )
    op = jg.OperatingPoint(torque=700.0, speed_rpm=10.0)
    res = postprocess(dyn, mesh, op, ws, stats, flow)
    assert int(res.status) == 0
    assert float(np.min(res.back_contact)) == 1.0  # on the back flanks all cycle
    rb = np.asarray(dyn.base_radius)
    q = np.asarray(res.displacement) * np.array([rb[0], 1, 1, rb[1], 1, 1])  # rφ in metres
    scale = float(np.max(back.static_te))
    along = np.asarray(dyn.back_deflection(q))
    err = np.abs(along + pair.backlash + np.asarray(back.static_te)) / scale
    assert np.median(err) < 1e-4
    assert np.sum(err > 0.01) <= 12  # the ringing next to the two load steps (measured 7 > 0.01)
    assert err.max() < 0.2
    # the mean mesh force balances the reversed torque (mean moment balance, 1e-5: the ringing)
    assert float(np.mean(res.mesh_force)) == pytest.approx(-float(mesh.total_load), rel=1e-4)
    w_load = float(mesh.total_load)
    c2 = math.cos(2 * float(gear_geometry(pair).operating_pressure_angle))
    s2 = math.sin(2 * float(gear_geometry(pair).operating_pressure_angle))
    b = pair.bearings
    expected = {
        1: w_load * c2 / float(b.ky[0]),
        2: -w_load * s2 / float(b.kx[0]),
        4: -w_load * c2 / float(b.ky[1]),
        5: w_load * s2 / float(b.kx[1]),
    }
    for k, value in expected.items():
        assert np.median(np.abs(q[:, k] / value - 1)) < 1e-4, k


def test_back_force_acts_along_the_back_flanks_line_of_action():
    # The plane of the gears as in the tooth-thickness test (gear 1 at O1 = 0, gear 2 above, LOA1
    # through T1 along d1, LOA2 its mirror image). The dynamics' axes: e_y along LOA1 from the
    # driver towards the driven gear (the drive force on gear 2 is +Fm e_y), e_x against gear 1's
    # tangential surface motion at the drive contact (module docstring of dynamics.model). Gear 1
    # turns so that its surface at the drive contact moves along +e_y (the driver does the work).
    # The back flanks' force on gear 1, f_b (−cos 2α_w e_y + sin 2α_w e_x) by the equations of
    # motion (f_b < 0), must lie along LOA2, the back flanks' common normal (the involute
    # construction above), and turn gear 1 forward: gear 2's back flank pushes it on.
    pair = jg.presets.li2015_pair()
    geo = gear_geometry(pair)
    rb, aw = float(geo.base_radius[0]), float(geo.operating_pressure_angle)
    t1, d1 = rb * np.array([math.sin(aw), math.cos(aw)]), np.array([-math.cos(aw), math.sin(aw)])
    t2, d2 = rb * np.array([-math.sin(aw), math.cos(aw)]), np.array([math.cos(aw), math.sin(aw)])
    dyn, mesh, _, _ = _back_dynamics(pair, 32)
    contact = t1 + float(mesh.contact_position[8, 0]) * d1

    def velocity(omega, r):
        return omega * np.array([-r[1], r[0]])

    omega1 = 1.0 if velocity(1.0, contact) @ d1 > 0 else -1.0
    v = velocity(omega1, contact)
    tangential = v - (v @ d1) * d1
    e_y, e_x = d1, -tangential / np.linalg.norm(tangential)
    c, s = (float(a) for a in dyn.back_direction())
    f1 = -1.0 * (-c * e_y + s * e_x)  # f_b = −1 N
    assert abs(f1 @ np.array([-d2[1], d2[0]])) < 1e-12  # along LOA2
    assert float(np.linalg.norm(f1)) == pytest.approx(1.0, rel=1e-12)
    back_point = t2 + 0.01 * d2
    moment = back_point[0] * f1[1] - back_point[1] * f1[0]
    assert moment * omega1 > 0  # turns gear 1 forward
    assert abs(abs(moment) - rb) < 1e-12  # at the base radius, as the drive force


def test_flank_forces_are_the_gradient_of_the_mesh_potential():
    # Every mesh force the equations of motion put on the six coordinates must be −∂V/∂q of
    # V = ½ km⟨d⟩² + ½ km_b⟨d_b⟩² (which makes the mesh conservative at frozen τ, as the
    # energy-balance test needs): checked at displacements in drive contact, apart and in back
    # contact (gears turned back through the clearance, bearings deflected both ways), from the
    # accelerations at rest with no friction: m a = Q_mesh + torques − bearing springs.
    from jaxgear.dynamics.model import _E, _KM

    pair = jg.presets.li2015_pair()
    dyn, mesh, _, _ = _back_dynamics(pair, 32)
    rb = np.asarray(dyn.base_radius)
    inertia = np.asarray(dyn.inertia) / rb**2
    masses = np.array([inertia[0], dyn.mass[0], dyn.mass[0], inertia[1], dyn.mass[1], dyn.mass[1]])
    springs = np.array([0.0, dyn.ky[0], dyn.kx[0], 0.0, dyn.ky[1], dyn.kx[1]])
    tau = 0.3

    def potential(q):
        km, d, km_b, d_b = dyn._flanks(tau, q)
        return 0.5 * km * jnp.maximum(d, 0.0) ** 2 + 0.5 * km_b * jnp.maximum(d_b, 0.0) ** 2

    tab = dyn.tables(tau)
    # a position in contact, with an excitation of micrometres: the cases below mean what they say
    assert float(tab[_KM]) > 0
    assert abs(float(tab[_E])) < 1e-4
    ell = float(dyn.half_clearance)
    cases = {
        "drive": [30e-6, -2e-6, 1e-6, 0.0, 2e-6, -1e-6],
        "apart": [-ell, 0.0, 0.0, 0.0, 0.0, 0.0],
        "back": [-2 * ell - 30e-6, 3e-6, -2e-6, 1e-6, -3e-6, 2e-6],
    }
    for name, q in cases.items():
        q = jnp.asarray(q)
        a = np.asarray(dyn.accelerations(tau, q, jnp.zeros(6), 0.0))
        torques = np.array(
            [float(dyn.torque) / rb[0], 0, 0, -float(dyn.load_torque(0.0)) / rb[1], 0, 0]
        )
        q_mesh = masses * a - torques + springs * np.asarray(q)
        grad = -np.asarray(jax.grad(potential)(q))
        scale = max(float(np.max(np.abs(grad))), 1.0)
        np.testing.assert_allclose(q_mesh, grad, atol=1e-9 * scale, err_msg=name)
        if name == "back":
            assert abs(grad[2]) > 0.1 * abs(grad[1])  # the back force has an x component


def _periodic_orbit_that_strikes_the_back_flanks_counts_their_loss(every_path):
    # With 5 µm of backlash (against the preset's 140 µm) the calibrated pair's stable periodic
    # orbit at 1500 N m and 3350 rpm strikes the back flanks over 22 % of the cycle (a dynamics
    # sweep every 25 rpm over 500-4200 rpm found such orbits only at 1500 N m, 3350-3375 rpm, with
    # 2-10 µm of backlash; none at 300 or 700 N m, nor with 20-140 µm). Their loss, on the
    # constant-μ rung Φ = μ Σ W us s (s = us/(us² + (0.02 um)²)^½: the rungs' sign of the sliding
    # speed, smoothed over 2 % slide-to-roll ratio), is computed here apart from the model's
    # machinery: the orbit's negative mesh force (the sum of its tooth forces) shared by the back
    # mesh's quasi-static load shares, at the kinematic speeds of its radii of curvature.
    import equinox as eqx

    from jaxgear.contact import SIGN_SLIDE_TO_ROLL

    pair = eqx.tree_at(lambda p: p.backlash, jg.presets.li2015_pair_calibrated(), 5e-6)
    lub, surf = jg.presets.mil_l_23699(), jg.presets.ground()
    fid = Fidelity(friction="constant", n_positions=32)
    op = jg.OperatingPoint(torque=1500.0, speed_rpm=3350.0)
    res = jg.simulate(pair, lub, surf, op, fid)
    assert int(res.status) == 0  # a stable periodic orbit, not an attractor
    assert float(res.back_contact_share) > 0.1  # measured 0.22
    force = np.asarray(res.tooth_force).sum(axis=1)
    back = back_flank_mesh(pair, op.torque, 32)
    omega1 = 3350.0 * math.pi / 30.0
    omega2 = omega1 * pair.teeth[0] / pair.teeth[1]
    rho = np.asarray(back.radius_of_curvature)
    u1, u2 = rho[..., 0] * omega1, rho[..., 1] * omega2
    us, um = u2 - u1, 0.5 * (u1 + u2)
    sliding = us**2 / np.sqrt(us**2 + (SIGN_SLIDE_TO_ROLL * um) ** 2)
    w = np.asarray(back.load_share) * np.maximum(-force, 0.0)[:, None]
    expected = float(np.mean(np.sum(float(fid.constant_mu) * w * sliding, axis=1)))
    assert expected > 0.02 * float(res.power_loss)  # measured 61.3 of 1489.0 W
    assert float(res.power_loss_back) == pytest.approx(expected, rel=1e-9)
    drive = float(np.mean(np.sum(np.asarray(res.power_loss_pair), axis=1)))
    assert float(res.power_loss) == pytest.approx(drive + float(res.power_loss_back), rel=1e-12)
    if not every_path:
        return
    # the same without the attractor branch (attractor_periods = 0 takes another path), and in a
    # vmapped sweep beside a speed without back contact (3325 rpm)
    off = jg.simulate(pair, lub, surf, op, fid.replace(attractor_periods=0))
    assert float(off.power_loss_back) == pytest.approx(expected, rel=1e-9)
    swept = jg.sweep(pair, lub, surf, op, speeds_rpm=[3325.0, 3350.0], fidelity=fid)
    np.testing.assert_allclose(np.asarray(swept.power_loss_back), [0.0, expected], rtol=1e-9)


def test_a_periodic_orbit_that_strikes_the_back_flanks_counts_their_loss():
    # simulate's own path (the attractor branch compiled in, as by default); the other two paths
    # compile a program each (~2/3 of the check's ~70 s CPU): the slow test below
    _periodic_orbit_that_strikes_the_back_flanks_counts_their_loss(every_path=False)


@pytest.mark.slow
def test_a_periodic_orbit_that_strikes_the_back_flanks_counts_their_loss_on_every_path():
    _periodic_orbit_that_strikes_the_back_flanks_counts_their_loss(every_path=True)
