"""State files from Python: kelp.SystemState and kelp.FleetState pickle (and deep-copy) through
kelp::sim's state files and step on bit for bit (BDF2 history, the kept Newton matrix, a winch
that has re-meshed, thrusters and batteries); kelp.save_state / kelp.load_state check the state
against the system; a corrupted pickle raises kelp.StateError."""

import copy
import json
import pickle

import numpy as np
import pytest

import kelp


def winch_pair(scenarios_dir):
    """winch_dive.json (a winch on the boat, both vehicles' thrusters) on a coarse tether."""
    sc = json.loads((scenarios_dir / "winch_dive.json").read_text())
    sc["tether"]["segment_length"] = 1.0
    return kelp.System.from_scenario(sc)


def pair_inputs(system, payout):
    u = system.inputs()
    u.asv_commands[:] = 0.3
    u.auv_commands[:] = -0.2
    u.auv_commands[0] = 0.6
    u.winch_payout_rate = payout
    return u


def stepped_pair(system, steps=330):
    """A state past its winch's first re-mesh, with its integrator history."""
    state = system.initial_state()
    nodes = state.tether_position.shape[0]
    u = pair_inputs(system, 0.5)
    for _ in range(steps):
        system.step(state, u, 0.01)
    assert state.tether_position.shape[0] > nodes  # the winch inserted nodes
    return state


def test_a_pickled_pair_state_steps_on_bit_for_bit(scenarios_dir):
    system = winch_pair(scenarios_dir)
    state = stepped_pair(system)
    data = pickle.dumps(state)
    back = pickle.loads(data)
    assert isinstance(back, kelp.SystemState)
    assert kelp.save_state(back) == kelp.save_state(state)
    deep = copy.deepcopy(state)
    # The original, its unpickled copy and a deep copy stepped with the same system (its
    # workspace follows whichever state it steps) through the winch reeling in.
    u = pair_inputs(system, -0.5)
    for _ in range(60):
        for s in (state, back, deep):
            system.step(s, u, 0.01)
    assert kelp.save_state(back) == kelp.save_state(state)
    assert kelp.save_state(deep) == kelp.save_state(state)
    assert np.array_equal(back.tether_position, state.tether_position)
    assert back.time == state.time


def test_load_state_checks_the_state_against_the_system(scenarios_dir):
    system = winch_pair(scenarios_dir)
    state = stepped_pair(system, steps=160)
    data = kelp.save_state(state)
    loaded = kelp.load_state(data, system)
    assert kelp.save_state(loaded) == data
    # The paper's system has no winch: the grown tether does not fit it.
    plain = kelp.System(tether_length=10, sea="calm", wave_components=4)
    with pytest.raises(kelp.StateError, match="nodes"):
        kelp.load_state(data, plain)
    # Nor do thrusters on a system without them.
    bare = kelp.System(tether_length=10, sea="calm", wave_components=4, propulsion=False)
    with pytest.raises(kelp.StateError, match="thrusters"):
        kelp.load_state(kelp.save_state(plain.initial_state()), bare)


def test_a_corrupted_or_foreign_pickle_raises_a_state_error(scenarios_dir):
    system = winch_pair(scenarios_dir)
    data = pickle.dumps(system.initial_state())
    at = data.index(b"\x89KELP")
    bad = bytearray(data)
    bad[at + 200] ^= 0x04  # one bit of the state file inside the pickle
    with pytest.raises(kelp.StateError, match="checksum mismatch"):
        pickle.loads(bytes(bad))
    assert issubclass(kelp.StateError, kelp.InvalidArgument)
    with pytest.raises(kelp.StateError, match="truncated"):
        kelp.load_state(kelp.save_state(system.initial_state())[:-9], system)
    with pytest.raises(kelp.StateError, match="not a kelp state file"):
        kelp.load_state(b"hello", system)
    # A NaN the step would refuse is not saved.
    state = system.initial_state()
    state.tether_velocity = np.full_like(state.tether_velocity, np.nan)
    with pytest.raises(kelp.StateError, match="velocities must be finite"):
        pickle.dumps(state)


def test_a_pickled_fleet_state_steps_on_bit_for_bit(scenarios_dir, tmp_path):
    sc = json.loads((scenarios_dir / "ship_tms_rov.json").read_text())
    for t in sc["fleet"]["tethers"]:
        t["segment_length"] = t["length"] / 10
    fleet = kelp.Fleet.from_scenario(sc)
    state = fleet.initial_state()
    u = fleet.inputs()
    u.commands(fleet.vehicle_index("rov"))[:] = 0.4
    u.winch_payout_rates[fleet.tether_index("tether")] = 0.5
    for _ in range(120):
        fleet.step(state, u, 0.01)
    back = pickle.loads(pickle.dumps(state))
    assert isinstance(back, kelp.FleetState)
    path = tmp_path / "fleet.kelpstate"
    kelp.save_state_file(str(path), state)
    from_file = kelp.load_state_file(str(path), fleet)
    for _ in range(40):
        for s in (state, back, from_file):
            fleet.step(s, u, 0.01)
    assert kelp.save_state(back) == kelp.save_state(state)
    assert kelp.save_state(from_file) == kelp.save_state(state)
    # A fleet's state is not a pair's.
    with pytest.raises(kelp.StateError, match="a pair state is expected"):
        kelp.load_state(kelp.save_state(state), winch_pair(scenarios_dir))
