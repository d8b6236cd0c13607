#!/usr/bin/env python3
"""Runs a scenario from Python with kelp.run_scenario and plots it with matplotlib: the ROV's and
the boat's tracks seen from above with the ROV's waypoints, the ROV's depth, its path error and
the tether's end forces against time.

    PYTHONPATH=<build>/python python3 examples/python/scenario_plot.py [scenario.json]
        [--duration S] [--seed N] [--out run.png]

The run is kelp-tethered-pair's (the same summary, bit for bit, for the same scenario and seed);
the samples come back as numpy columns named as timeseries.csv's.
"""
import argparse

import kelp


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario", nargs="?", help="scenario file (default: the embedded run)")
    p.add_argument("--duration", type=float, help="simulated time [s] (default: the scenario's)")
    p.add_argument("--seed", type=int, help="the sea's seed (default: the scenario's)")
    p.add_argument("--out", default="scenario_plot.png", help="the figure (PNG)")
    a = p.parse_args()

    summary, ts = kelp.run_scenario(a.scenario, duration=a.duration, seed=a.seed,
                                    timeseries=True)
    print(f"{summary['simulated_s']:.1f} s simulated: ROV RMS path error "
          f"{summary['auv']['rms_path_error_m']:.2f} m, boat RMS distance "
          f"{summary['asv']['rms_distance_to_auv_m']:.2f} m, max tension "
          f"{summary['tether']['max_tension_n']:.1f} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = ts["t"]
    fig, (top, depth, error, pull) = plt.subplots(1, 4, figsize=(17, 4.5))
    # NED: east (y) to the right, north (x) up.
    top.plot(ts["auv_y"], ts["auv_x"], label="ROV")
    top.plot(ts["asv_y"], ts["asv_x"], label="boat")
    top.plot(ts["auv_target_y"], ts["auv_target_x"], "k+", label="ROV's target")
    top.set(xlabel="east [m]", ylabel="north [m]", title="tracks", aspect="equal")
    top.legend()
    depth.plot(t, ts["auv_z"])
    depth.invert_yaxis()
    depth.set(xlabel="time [s]", ylabel="depth [m]", title="ROV depth")
    error.plot(t, ts["auv_error"], label="ROV from its path")
    error.plot(t, ts["asv_error"], label="boat from the ROV (horizontal)")
    error.set(xlabel="time [s]", ylabel="[m]", title="errors")
    error.legend()
    pull.plot(t, ts["tension_asv"], label="at the boat")
    pull.plot(t, ts["tension_auv"], label="at the ROV")
    pull.set(xlabel="time [s]", ylabel="force [N]", title="tether end forces")
    pull.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
