"""The library from Python: vehicles, environment, catenary and the coupled system, with numpy
arrays, zero-copy views where promised (and no dangling view), and kelp's exceptions with their
messages for bad input."""

import copy
import gc
import math

import numpy as np
import pytest

import kelp


# ---- vehicles ---------------------------------------------------------------------------------

def test_vehicle_presets_and_thrusters():
    rov = kelp.Vehicle.bluerov2_heavy()
    boat = kelp.Vehicle.blueboat()
    assert rov.thruster_count == 8 and boat.thruster_count == 2
    assert rov.thruster_positions.shape == (8, 3)
    np.testing.assert_allclose(np.linalg.norm(rov.thruster_directions, axis=1), 1.0)
    assert rov.mass == pytest.approx(13.5)  # von Benzon et al. 2022, Table A1
    m = rov.mass_matrix
    assert m.shape == (6, 6)
    np.testing.assert_allclose(m, m.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    # Slightly buoyant in seawater (B - W = 2.3 N, presets' doc).
    assert rov.buoyancy - rov.weight == pytest.approx(2.3, abs=0.1)
    # Read-only views of the allocation, alive after the vehicle is gone.
    p = rov.thruster_positions
    assert not p.flags.writeable
    del rov
    gc.collect()
    assert p.shape == (8, 3) and np.isfinite(p).all()


def test_vehicle_step_follows_thrust_and_refuses_bad_input():
    rov = kelp.Vehicle.bluerov2_heavy()
    x = kelp.VehicleState(position=[0, 0, 10])
    # ArduSub's "forward" pattern (README's hello vehicle).
    u = np.array([-0.5, -0.5, 0.5, 0.5, 0, 0, 0, 0])
    tau = rov.wrench(kelp.t200_thrust(u))
    assert tau.shape == (6,) and tau[0] > 0
    for _ in range(1000):
        rov.step(x, 1e-2, tau=tau, current=[0.2, 0, 0])
    assert x.time == pytest.approx(10.0)
    assert x.nu[0] > 0.3 and x.position[0] > 1.0
    before = x.copy()
    with pytest.raises(kelp.InvalidArgument, match="tau: expected shape \\(6,\\), got \\(5,\\)"):
        rov.step(x, 1e-2, tau=np.zeros(5))
    with pytest.raises(kelp.InvalidArgument, match="dt"):
        rov.step(x, -1.0)
    x.nu[2] = math.nan
    with pytest.raises(kelp.InvalidArgument, match="nu") as info:
        rov.step(x, 1e-2)
    assert isinstance(info.value, ValueError)
    x.nu[2] = before.nu[2]
    np.testing.assert_array_equal(x.position, before.position)  # unchanged by the failed steps
    with pytest.raises(kelp.InvalidArgument, match="thrust: expected shape \\(8,\\)"):
        rov.wrench(np.zeros(3))
    with pytest.raises(kelp.InvalidArgument, match="expected an array of numbers"):
        rov.step(x, 1e-2, tau="abc")


def test_vehicle_state_views_are_zero_copy_and_outlive_nothing():
    x = kelp.VehicleState(position=[1, 2, 3], attitude=[0, 0, 0, 1], nu=np.arange(6.0))
    p = x.position
    assert np.shares_memory(p, x.position)
    p[0] = 5.0  # writing into the view writes the state
    assert x.position[0] == 5.0
    x.euler = [0.0, 0.0, math.pi / 2]
    np.testing.assert_allclose(x.attitude, [0, 0, math.sqrt(0.5), math.sqrt(0.5)])
    np.testing.assert_allclose(x.rotation() @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    # The view keeps its owner alive: no dangling memory after `del`.
    nu = x.nu
    del x
    gc.collect()
    np.testing.assert_array_equal(nu, np.arange(6.0))
    c = kelp.VehicleState()
    d = copy.deepcopy(c)
    d.position[2] = 1
    assert c.position[2] == 0


def test_t200_is_asymmetric_and_vectorised():
    f = kelp.t200_thrust(np.array([[-1.0, 0.0, 1.0]]), 16.0)
    assert f.shape == (1, 3)
    # About 5.25 kgf forward and 4.1 kgf reverse at 16 V (Blue Robotics' T200 data).
    assert f[0, 2] == pytest.approx(5.25 * 9.80665, rel=0.1)
    assert -f[0, 0] == pytest.approx(4.1 * 9.80665, rel=0.1)
    assert f[0, 1] == 0


# ---- environment ------------------------------------------------------------------------------

def test_environment_sample_is_vectorised_and_matches_single_points():
    env = kelp.Environment.preset("moderate", seed=3)
    pts = np.array([[0.0, 0.0, 2.0], [5.0, -3.0, 8.0], [1.0, 1.0, 30.0]])
    s = env.sample(pts, 12.5)
    assert s["current"].shape == (3, 3) and s["surface_elevation"].shape == (3,)
    assert s["surface_slope"].shape == (3, 2)
    one = env.sample(pts[1], 12.5)
    np.testing.assert_array_equal(one["wave_velocity"], s["wave_velocity"][1])
    assert one["surface_elevation"] == s["surface_elevation"][1]
    # Orbital velocity decays with depth (deep water: e^{-k z}).
    speed = np.linalg.norm(s["wave_velocity"], axis=1)
    assert speed[2] < speed[0]
    # The paper's moderate current: 0.5 m/s towards 45 degrees.
    np.testing.assert_allclose(np.linalg.norm(s["current"][0]), 0.5, rtol=1e-9)
    eta = env.surface_elevation(pts, 12.5)  # its own kernel: the same to round-off
    np.testing.assert_allclose(eta, s["surface_elevation"], rtol=1e-12, atol=1e-14)
    assert env.surface_elevation(pts[:, :2], 12.5).shape == (3,)
    # Hs = 4 std(eta) over a long record, within sampling error.
    t = np.arange(0, 1200, 0.5)
    record = np.array([env.surface_elevation([0.0, 0.0], ti) for ti in t])
    assert 4 * record.std() == pytest.approx(3.0, rel=0.2)


def test_environment_presets_and_errors():
    calm = kelp.Environment()
    assert calm.water_density == 1025.0 and calm.gravity == pytest.approx(9.80665)
    assert calm.surface_elevation([1.0, 2.0, 0.0], 3.0) == 0.0
    with pytest.raises(kelp.InvalidArgument, match="points: expected shape \\(n, 3\\)"):
        calm.sample(np.zeros((4, 2)), 0.0)
    # A point with a NaN or infinite coordinate is refused, in calm water too (no silent zeros).
    with pytest.raises(kelp.InvalidArgument):
        calm.sample([0.0, math.nan, 1.0], 0.0)
    with pytest.raises(kelp.InvalidArgument):
        calm.sample([[0.0, 0.0, 1.0], [math.inf, 0.0, 1.0]], 0.0)
    with pytest.raises(kelp.InvalidArgument, match='sea: expected "calm"'):
        kelp.Environment.preset("stormy")
    waves = kelp.Environment.sea_state(significant_height=1.0, peak_period=6.0)
    with pytest.raises(kelp.InvalidArgument):
        waves.surface_elevation([0.0, 0.0], math.nan)


def test_environment_regular_wave_is_airy():
    # A regular wave alone: elevation A cos(k x - w t) at a probe, velocity the closed form.
    for depth in (math.inf, 12.0):
        env = kelp.Environment.sea_state(
            regular={"height": 1.0, "period": 5.0}, seabed_depth=depth)
        w = 2 * math.pi / 5.0
        k = w * w / 9.80665
        if math.isfinite(depth):  # w^2 = g k tanh(k h), by fixed-point iteration
            for _ in range(200):
                k = w * w / (9.80665 * math.tanh(k * depth))
        t = np.linspace(0.0, 20.0, 81)
        zeta = [env.surface_elevation([7.0, 0.0, 0.0], ti) for ti in t]
        np.testing.assert_allclose(zeta, 0.5 * np.cos(k * 7.0 - w * t), atol=1e-9)
        z, ti = 2.0, 1.3
        th = k * 7.0 - w * ti
        if math.isinf(depth):
            fh = fv = math.exp(-k * z)
        else:
            fh = math.cosh(k * (depth - z)) / math.sinh(k * depth)
            fv = math.sinh(k * (depth - z)) / math.sinh(k * depth)
        s = env.sample([7.0, 0.0, z], ti, with_wind=False)
        np.testing.assert_allclose(
            s["wave_velocity"], [0.5 * w * fh * math.cos(th), 0.0, -0.5 * w * fv * math.sin(th)],
            atol=1e-9)
    # On a JONSWAP sea, by wavelength, in several directions; Wheeler stretching at a trough's
    # surface gives the mean-level velocity.
    both = kelp.Environment.sea_state(
        significant_height=1.0, peak_period=6.0,
        regular=[{"height": 0.4, "wavelength": 30.0, "direction": 0.5, "phase": 1.0},
                 {"height": 0.2, "period": 4.0}],
        stretching="wheeler")
    assert np.isfinite(both.surface_elevation([1.0, 2.0, 0.0], 3.0))
    lone = kelp.Environment.sea_state(regular={"height": 1.0, "period": 6.0}, stretching="wheeler")
    w = 2 * math.pi / 6.0
    trough_t = math.pi / w  # cos(-w t) = -1 at x = 0
    top = lone.sample([0.0, 0.0, 0.5 + 1e-12], trough_t, with_wind=False)
    np.testing.assert_allclose(top["wave_velocity"], [-0.5 * w, 0.0, 0.0], atol=1e-9)
    # Bad input, named.
    with pytest.raises(kelp.InvalidArgument, match="regular.height"):
        kelp.Environment.sea_state(regular={"height": -1.0, "period": 5.0})
    with pytest.raises(kelp.InvalidArgument, match="exactly one of regular.period"):
        kelp.Environment.sea_state(regular={"height": 1.0, "period": 5.0, "wavelength": 40.0})
    with pytest.raises(kelp.InvalidArgument, match="breaking limit"):
        kelp.Environment.sea_state(regular={"height": 9.0, "wavelength": 40.0})
    with pytest.raises(kelp.InvalidArgument, match='unknown key "amplitude"'):
        kelp.Environment.sea_state(regular={"amplitude": 1.0, "period": 5.0})
    with pytest.raises(kelp.InvalidArgument, match="expected a dict"):
        kelp.Environment.sea_state(regular=3.0)
    with pytest.raises(kelp.InvalidArgument, match="stretching"):
        kelp.Environment.preset("moderate", stretching="delta")


# ---- catenary ---------------------------------------------------------------------------------

def test_catenary_solves_the_papers_equations():
    D, dz, L, w = 6.0, 2.0, 10.0, 1.5
    r = kelp.catenary(horizontal=D, vertical=dz, length=L, weight_per_length=w)
    assert r.status == "converged" and r.ok
    a, c = r.a, r.c
    assert a * (math.cosh((D - c) / a) - math.cosh(c / a)) == pytest.approx(dz, abs=1e-10)
    assert a * (math.sinh((D - c) / a) + math.sinh(c / a)) == pytest.approx(L, abs=1e-10)
    assert r.horizontal_tension == pytest.approx(a * w)
    # The two ends carry the whole weight between them.
    assert r.vertical_force_start + r.vertical_force_end == pytest.approx(w * L, rel=1e-9)
    assert r.tension_end > r.tension_start  # the higher end carries more
    pts = r.points(11)
    assert pts.shape == (11, 3)
    np.testing.assert_allclose(pts[-1], [D, 0, -dz], atol=1e-9)


def test_catenary_statuses_not_exceptions():
    assert kelp.catenary(horizontal=5, vertical=0, length=4, weight_per_length=1).status == "taut"
    assert kelp.catenary(horizontal=0, vertical=1, length=4, weight_per_length=1).status == "vertical"
    bad = kelp.catenary(horizontal=math.nan, vertical=0, length=4, weight_per_length=1)
    assert bad.status == "invalid_input" and math.isnan(bad.a)
    with pytest.raises(TypeError):
        kelp.catenary(5, 0, 4, 1)  # keywords only


# ---- the system -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def system():
    return kelp.System(tether_length=10, sea="moderate", seed=2, ramp=5.0)


def test_system_steps_and_reports(system):
    x = system.initial_state()
    u = system.inputs()
    assert u.auv_commands.shape == (8,) and u.asv_commands.shape == (2,)
    n = system.tether_nodes
    assert x.tether_position.shape == (n, 3) == x.tether_velocity.shape
    np.testing.assert_allclose(x.tether_position[-1],
                               x.auv.point_position(system.auv_attachment), atol=1e-9)
    u.auv_commands[4:] = -0.3  # vertical thrusters up
    for _ in range(50):
        r = system.step(x, u, 0.01)
    assert x.time == pytest.approx(0.5)
    assert r.substeps >= 1 and r.force_on_auv.shape == (3,)
    assert np.isfinite(x.tether_position).all()
    assert np.any(x.auv_thrust != 0)
    e = system.step(x, u, 0.01, with_energy=True).energy
    assert e["total"] == pytest.approx(e["asv"] + e["auv"] + e["tether"])
    assert e["total"] == pytest.approx(system.energy(x)["total"])


def test_system_state_copy_reproduces_bit_for_bit(system):
    x = system.initial_state()
    u = system.inputs()
    u.auv_commands[:] = 0.2
    for _ in range(20):
        system.step(x, u, 0.01)
    saved = x.copy()
    for _ in range(30):
        system.step(x, u, 0.01)
    for _ in range(30):
        system.step(saved, u, 0.01)
    np.testing.assert_array_equal(saved.tether_position, x.tether_position)
    np.testing.assert_array_equal(saved.auv.position, x.auv.position)


def test_system_views_share_memory_and_keep_their_owner(system):
    x = system.initial_state()
    pos = x.tether_position
    assert np.shares_memory(pos, x.tether_position)
    auv = x.auv
    p = auv.position
    system.step(x, None, 0.01)
    np.testing.assert_array_equal(p, x.auv.position)  # the view follows the state
    assert np.shares_memory(p, x.auv.position)
    del x, auv
    gc.collect()
    assert np.isfinite(pos).all() and np.isfinite(p).all()  # still valid memory
    u = system.inputs()
    t = u.auv_commands
    t[:] = 0.5
    assert np.all(u.auv_commands == 0.5)


def test_system_bad_input_leaves_the_state(system):
    x = system.initial_state()
    before = x.copy()
    u = system.inputs()
    u.auv_tau[0] = math.nan
    with pytest.raises(kelp.InvalidArgument, match="inputs.auv.tau"):
        system.step(x, u, 0.01)
    with pytest.raises(kelp.InvalidArgument, match="auv_commands: expected shape \\(8,\\)"):
        u.auv_commands = np.zeros(3)
    x.auv.nu[0] = math.nan
    with pytest.raises(kelp.InvalidArgument, match="nu"):
        system.step(x, None, 0.01)
    x.auv.nu[0] = before.auv.nu[0]
    with pytest.raises(kelp.InvalidArgument, match="dt"):
        system.step(x, None, 0.0)
    with pytest.raises(kelp.InvalidArgument, match="tether_position: expected shape"):
        x.tether_position = np.zeros((3, 3))
    np.testing.assert_array_equal(x.tether_position, before.tether_position)
    assert x.time == before.time
    with pytest.raises(kelp.InvalidArgument, match='sea: expected'):
        kelp.System(sea="stormy")


def test_system_from_scenario_starts_like_a_run():
    s = kelp.System.from_scenario({"sea": "calm", "tether": {"length": 12}})
    assert s.tether_parameters["length"] == 12
    x = s.initial_state()
    assert x.time == 0
    with pytest.raises(kelp.ScenarioError, match=r"\(dict\): /tether/lenght"):
        kelp.System.from_scenario({"tether": {"lenght": 12}})


def test_help_is_useful():
    doc = kelp.System.__doc__
    assert "step" in doc and "from_scenario" in doc
    for name in ("step", "initial_state", "inputs", "energy", "from_scenario"):
        assert getattr(kelp.System, name).__doc__
    for cls in (kelp.Vehicle, kelp.VehicleState, kelp.Environment, kelp.Catenary,
                kelp.SystemState, kelp.SystemInputs, kelp.SystemReport, kelp.Tether,
                kelp.TetherState):
        assert cls.__doc__
        for k, v in vars(cls).items():
            if not k.startswith("_"):
                assert getattr(v, "__doc__", None), f"{cls.__name__}.{k} has no docstring"


# ---- the tether on its own ------------------------------------------------------------------

def test_tether_static_shape_matches_the_catenary_and_stays():
    t = kelp.Tether.rov_tether(10.0, 0.5)
    assert t.nodes == 21 and t.segment_length == pytest.approx(0.5)
    # Deep enough that the buoyant line's arch (w < 0) stays under the surface.
    start, end = np.array([0.0, 0.0, 5.0]), np.array([6.0, 0.0, 7.0])
    x = t.initial_state(start, end)
    assert x.position.shape == (21, 3)
    np.testing.assert_allclose(x.position[0], start, atol=1e-12)
    np.testing.assert_allclose(x.position[-1], end, atol=1e-12)
    w = t.weight_per_length()
    assert w < 0  # slightly buoyant in seawater
    cat = kelp.catenary(horizontal=6.0, vertical=-2.0, length=10.0, weight_per_length=w)
    assert cat.ok
    np.testing.assert_allclose(x.position, cat.points(21) + start, atol=1e-6)
    # Held between fixed ends in still water the line stays near its catenary, and the ends
    # feel the catenary's pull (direction of the force on the start end).
    for _ in range(200):
        f = t.step(x, start, end, 0.01)
    assert x.time == pytest.approx(2.0)
    mid = x.position[10]
    np.testing.assert_allclose(mid, cat.points(21)[10] + start, atol=0.05)
    assert f["substeps"] >= 1 and f["force_on_start"].shape == (3,)
    assert np.all(np.isfinite(x.velocity))
    pos = x.position
    del x
    gc.collect()
    assert pos.shape == (21, 3)  # the view kept its state alive


def test_tether_bad_input():
    t = kelp.Tether.rov_tether(10.0, 0.5)
    x = t.initial_state([0, 0, 0], [6, 0, 2])
    before = x.copy()
    with pytest.raises(kelp.InvalidArgument, match="end: expected shape \\(3,\\)"):
        t.step(x, [0, 0, 0], [6, 0], 0.01)
    with pytest.raises(kelp.InvalidArgument, match="duration"):
        t.step(x, [0, 0, 0], [6, 0, 2], -0.01)
    with pytest.raises(kelp.InvalidArgument, match="length"):
        kelp.Tether.rov_tether(-1.0)
    with pytest.raises(kelp.InvalidArgument, match="position: expected shape \\(21, 3\\)"):
        x.position = np.zeros((20, 3))
    np.testing.assert_array_equal(x.position, before.position)


def test_tether_internal_damping_ratio():
    # MoorDyn's BA/-zeta: BA = zeta * segment length * sqrt(EA * mass per length), the same
    # damper BA/l for any segment length; the preset's own BA is 100 N s.
    assert kelp.Tether.rov_tether(10.0, 0.5).internal_damping == 100.0
    d = 7.6e-3
    area = np.pi * d * d / 4
    ea, mu = 6.437e7 * area, 1000.0 * area
    dampers = []
    for seg in (0.25, 0.5, 1.0):
        t = kelp.Tether.rov_tether(10.0, seg, internal_damping_ratio=0.8)
        assert t.internal_damping == pytest.approx(0.8 * t.segment_length * np.sqrt(ea * mu),
                                                   rel=1e-12)
        dampers.append(t.internal_damping / t.segment_length)
    assert dampers == pytest.approx([dampers[0]] * 3, rel=1e-12)
    with pytest.raises(kelp.InvalidArgument, match="internal_damping_ratio"):
        kelp.Tether.rov_tether(10.0, 0.5, internal_damping_ratio=-1.0)
