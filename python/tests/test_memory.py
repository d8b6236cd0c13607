"""No memory growth over 10^5 steps of the coupled system from Python (views taken and dropped
every step, a report returned by every step)."""

import gc
import resource

import numpy as np

import kelp


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def test_no_memory_growth_over_1e5_steps():
    system = kelp.System(sea="calm")
    x = system.initial_state()
    u = system.inputs()
    total = 0.0
    for _ in range(2000):  # warm-up: every cache and pool in place
        r = system.step(x, u, 0.01)
        total += x.auv.position[2] + r.force_on_auv[2] + x.tether_position[5, 2]
    gc.collect()
    before = rss_kib()
    for _ in range(100_000):
        r = system.step(x, u, 0.01)
        total += x.auv.position[2] + r.force_on_auv[2] + x.tether_position[5, 2]
    gc.collect()
    grown = rss_kib() - before
    assert np.isfinite(total)
    assert x.time > 1000.0
    # A leak of even one 24-byte object a step would be 2.4 MB.
    assert grown < 1024, f"RSS grew by {grown} KiB over 1e5 steps"
