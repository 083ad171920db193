#!/usr/bin/env python3
"""Compares the ground truth of two recorded runs (docs/hardware.md, "Sim vs hw").

    hw_bridge/tools/compare_runs.py RUN_A RUN_B [--until S] [--build DIR]

RUN_A, RUN_B: run folders of tools/launch.sh (log.lcm, config.yaml). Each is
exported to RUN/csv with stewart_log_export if that folder is missing.

Time is aligned on scenario time: the controller's scenario clock starts at
the first state it accepts, which is when it publishes its first setpoint,
so t = utime - utime(first STEWART_SETPOINT) in both runs, whatever their
time bases (plant_sim lockstep counts from 0, hw_bridge from the Unix epoch).
Run B's ground truth is interpolated linearly at run A's sample times.

Prints, over scenario time [0, --until]: max |q_A - q_B| and max |qd_A - qd_B|
per axis, and per run the extremes on ground truth against each configured
position and velocity limit. Standard library and PyYAML only.
"""
import argparse
import bisect
import csv
import os
import subprocess
import sys

import yaml

AXES = ["x", "y", "z", "phi", "theta", "psi"]
Q = ["q_x_m", "q_y_m", "q_z_m", "q_phi_rad", "q_theta_rad", "q_psi_rad"]
QD = ["qd_x_mps", "qd_y_mps", "qd_z_mps", "qd_phi_radps", "qd_theta_radps", "qd_psi_radps"]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def channel(config, name):
    lcm = config["lcm"]
    return lcm["channel_prefix"] + lcm["channels"][name] + (lcm.get("channel_suffix") or "")


def load_run(run, build):
    csv_dir = os.path.join(run, "csv")
    if not os.path.isdir(csv_dir):
        exporter = os.path.join(build, "tools", "stewart_log_export")
        subprocess.run([exporter, os.path.join(run, "log.lcm"), "--out", csv_dir], check=True,
                       stdout=subprocess.DEVNULL)
    with open(os.path.join(run, "config.yaml")) as f:
        config = yaml.safe_load(f)
    truth = read_csv(os.path.join(csv_dir, channel(config, "state_truth") + ".csv"))
    setpoints = read_csv(os.path.join(csv_dir, channel(config, "setpoint") + ".csv"))
    if not truth or not setpoints:
        sys.exit(f"compare_runs: {run} has no ground truth or no setpoint")
    t0 = int(setpoints[0]["utime_us"])
    samples = [((int(r["utime_us"]) - t0) * 1e-6, [float(r[k]) for k in Q],
                [float(r[k]) for k in QD]) for r in truth]
    return config, samples


def limit_report(name, config, samples, until):
    window = [s for s in samples if 0.0 <= s[0] <= until]
    print(f"{name}: {len(window)} truth samples in [0, {until:g}] s")
    safety = config["safety"]
    for kind, key, index in (("position", "position_limits", 1), ("velocity", "velocity_limits", 2)):
        for limit in safety.get(key, []):
            axis = AXES.index(limit["axis"])
            values = [s[index][axis] for s in window]
            for side, sign in (("upper", 1.0), ("lower", -1.0)):
                if side not in limit:
                    continue
                bound = float(limit[side])
                worst = max(values, key=lambda v: sign * (v - bound))
                excess = max(0.0, sign * (worst - bound))
                print(f"  {kind} {limit['axis']} {side} {bound:g}: extreme {worst:.5f}, "
                      f"exceeded by {excess:.2e}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_a")
    parser.add_argument("run_b")
    parser.add_argument("--until", type=float, default=20.0, help="end of the window (s)")
    parser.add_argument("--build", default=os.environ.get("STEWART_BUILD_DIR", "build"))
    args = parser.parse_args()
    config_a, a = load_run(args.run_a, args.build)
    config_b, b = load_run(args.run_b, args.build)
    times_b = [s[0] for s in b]
    max_dq = [0.0] * 6
    max_dqd = [0.0] * 6
    at = [0.0] * 6
    for t, q, qd in a:
        if not 0.0 <= t <= args.until:
            continue
        k = bisect.bisect(times_b, t)
        if k == 0 or k >= len(b):
            continue
        (t1, q1, qd1), (t2, q2, qd2) = b[k - 1], b[k]
        w = (t - t1) / (t2 - t1) if t2 > t1 else 0.0
        for i in range(6):
            dq = abs(q[i] - (q1[i] + w * (q2[i] - q1[i])))
            if dq > max_dq[i]:
                max_dq[i], at[i] = dq, t
            max_dqd[i] = max(max_dqd[i], abs(qd[i] - (qd1[i] + w * (qd2[i] - qd1[i]))))
    print(f"A = {args.run_a}\nB = {args.run_b}\nscenario time [0, {args.until:g}] s")
    print("max |q_A - q_B|:   " +
          ", ".join(f"{n} {v:.2e} (t {t:.2f})" for n, v, t in zip(AXES, max_dq, at)))
    print("max |qd_A - qd_B|: " + ", ".join(f"{n} {v:.2e}" for n, v in zip(AXES, max_dqd)))
    limit_report("A", config_a, a, args.until)
    limit_report("B", config_b, b, args.until)


if __name__ == "__main__":
    main()
