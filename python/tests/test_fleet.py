"""kelp.Fleet: a fleet scenario's physics stepped from Python (kelp::system's fleet step): a
weight hanging from an anchor settles where statics says, a saved state steps again bit for bit,
and bad parts are refused."""

import copy
import math

import numpy as np
import pytest

import kelp

# A 40 kg weight of 5 L on a 10 m line (12 mm, 0.15 kg/m, EA 1e5 N, internal damping ratio 50 so
# that its bounce settles in seconds) below an anchor at 5 m, in calm water: the line hangs
# straight down and the anchor carries both submerged weights.
MASS, VOLUME, DIAMETER, MU, LENGTH, EA = 40.0, 0.005, 0.012, 0.15, 10.0, 1e5


def hanging(**tether):
    return {
        "duration": 30,
        "sea": "calm",
        "fleet": {
            "anchors": [{"name": "buoy", "position": [0, 0, 5]}],
            "point_masses": [{"name": "weight", "mass": MASS, "volume": VOLUME,
                              "drag_area": 0.05, "start": [0, 0, 15]}],
            "tethers": [dict({"name": "line", "from": "buoy", "to": "weight", "length": LENGTH,
                              "segment_length": 0.5, "diameter": DIAMETER,
                              "mass_per_length": MU, "axial_stiffness": EA,
                              "internal_damping_ratio": 50}, **tether)],
        },
    }


def test_a_hanging_weight_loads_its_anchor_with_the_submerged_weights():
    fleet = kelp.Fleet.from_scenario(hanging())
    assert fleet.point_mass_names == ["weight"] and fleet.tether_names == ["line"]
    assert fleet.vehicle_names == []
    state = fleet.initial_state()
    u = fleet.inputs()
    start, end = np.zeros(3), np.zeros(3)
    for k in range(3000):  # 30 s: released unstretched, the weight bounces and settles
        report = fleet.step(state, u, 0.01)
        if k >= 2900:  # the last second's mean
            start += report.force_at_start[0] / 100
            end += report.force_at_end[0] / 100
    rho, g = fleet.environment.water_density, fleet.environment.gravity
    wet_weight = (MASS - rho * VOLUME) * g
    wet_line = (MU - rho * math.pi * DIAMETER**2 / 4) * g  # per metre
    # The anchor is pulled down (NED +z) by the weight and the line below it.
    assert start[2] == pytest.approx(wet_weight + wet_line * LENGTH, rel=0.01)
    assert abs(start[0]) < 1e-3 * start[2] and abs(start[1]) < 1e-3 * start[2]
    # The weight feels the line's pull up: its own submerged weight.
    assert -end[2] == pytest.approx(wet_weight, rel=0.01)
    # It hangs below the anchor by the line's length and its stretch under the tension
    # T(s) = W + w s (s up from the weight): (W L + w L^2 / 2) / EA.
    stretch = (wet_weight * LENGTH + wet_line * LENGTH**2 / 2) / EA
    z = state.point_mass_position(0)[2]
    assert z - 15.0 == pytest.approx(stretch, rel=0.02)
    assert np.allclose(state.tether_position(0)[:, :2], 0, atol=1e-6)
    assert report.force_at_start.shape == (1, 3)


def test_a_saved_state_steps_again_bit_for_bit():
    fleet = kelp.Fleet.from_scenario(hanging())
    state = fleet.initial_state()
    state.point_mass_velocity(0)[:] = [0.3, -0.2, 0.1]  # set swinging, in place
    for _ in range(50):
        fleet.step(state)
    saved = state.copy()
    again = copy.deepcopy(state)
    for s in (state, saved, again):
        for _ in range(100):
            fleet.step(s, dt=0.01)
    for s in (saved, again):
        assert s.time == state.time
        assert np.array_equal(s.tether_position(0), state.tether_position(0))
        assert np.array_equal(s.point_mass_position(0), state.point_mass_position(0))
    energy = fleet.energy(state)
    assert set(energy) == {"vehicles", "point_masses", "tethers", "total"}
    assert energy["total"] == pytest.approx(sum(energy["point_masses"]) + sum(energy["tethers"]))


def test_vehicles_by_name_and_their_commands(scenarios_dir):
    fleet = kelp.Fleet.from_scenario(scenarios_dir / "ship_tms_rov.json")
    assert fleet.vehicle_names == ["rov"]  # the ship is an anchor, the TMS a point mass
    assert fleet.point_mass_names == ["tms"]
    rov = fleet.vehicle_index("rov")
    assert fleet.vehicle_names[rov] == "rov"
    u = fleet.inputs()
    assert u.commands(rov).shape == (8,)  # a BlueROV2 Heavy
    state = fleet.initial_state()
    start = state.vehicle(rov).position.copy()
    u.commands(rov)[:] = 0.0
    u.tau(rov)[2] = 40.0  # push it down for a second
    for _ in range(100):
        fleet.step(state, u)
    assert state.vehicle(rov).position[2] > start[2] + 0.05
    k = fleet.tether_index("umbilical")
    assert fleet.tether_nodes(state, k) == state.tether_position(k).shape[0]
    with pytest.raises(kelp.InvalidArgument, match="no vehicle named"):
        fleet.vehicle_index("auv")
    with pytest.raises(kelp.InvalidArgument, match="out of range"):
        state.vehicle(len(fleet.vehicle_names))


def test_bad_fleets_and_bad_steps_are_refused_naming_the_part(scenarios_dir):
    with pytest.raises(kelp.ScenarioError, match="not a fleet scenario"):
        kelp.Fleet.from_scenario(scenarios_dir / "calm_hold.json")
    with pytest.raises(kelp.ScenarioError, match="/fleet/tethers/0/name"):
        kelp.Fleet.from_scenario(hanging(name="a line"))
    fleet = kelp.Fleet.from_scenario(hanging())
    state = fleet.initial_state()
    before = state.tether_position(0).copy()
    with pytest.raises(kelp.InvalidArgument):
        fleet.step(state, dt=-0.01)
    assert np.array_equal(state.tether_position(0), before)
    with pytest.raises(kelp.InvalidArgument, match="shape"):
        state.set_tether_position(0, np.zeros((3, 3)))
