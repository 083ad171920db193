#!/usr/bin/python3
"""Paper Fig. 4: uniform vs weighted alpha on the z axis.

Runs the paper scenario twice in one process (stewart_closed_loop_sim: plant,
sensors, EKF, controller, filter; deterministic for a seed), once with the
config's weights (z velocity alpha_v = 2, as in the paper's simulation) and
once with every alpha_v = 1 (uniform), and plots z, dz/dt and the composed
velocity barrier over the z moves (t = 18..40 s).

In the alpha-weighted LSE the class-K gain is 1 and alpha_i scales barrier i
inside the soft minimum: a larger alpha_v on z makes the z barrier look
farther from its limit, so the composition lets z use more of its own margin
before it dominates the others (docs/safety.md).

Usage: tools/plots/fig4_alpha.py OUT.png [--build DIR] [--config FILE]
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import yaml  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def find_tool(build):
    for dirpath, _, files in os.walk(build):
        if "stewart_closed_loop_sim" in files:
            return os.path.join(dirpath, "stewart_closed_loop_sim")
    sys.exit(f"fig4_alpha: stewart_closed_loop_sim not found under {build}: build first")


def run(tool, config_path, csv_path):
    subprocess.run([tool, "--config", config_path, "--scenario", "paper", "--csv", csv_path],
                   check=True, stdout=subprocess.DEVNULL)
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    cols = {k: [float(r[k]) for r in rows] for k in ("t", "q_z", "qd_z", "h_vel")}
    return cols


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--build", default=os.environ.get("STEWART_BUILD_DIR",
                                                          os.path.join(ROOT, "build")))
    parser.add_argument("--config", default=os.path.join(ROOT, "config", "platform.yaml"))
    args = parser.parse_args()
    tool = find_tool(args.build)
    with open(args.config) as f:
        text = f.read()
    weighted = yaml.safe_load(text)
    # Edit the text, not a re-dump: PyYAML would turn values like `off` into booleans.
    uniform_text = re.sub(r"(alpha_v:\s*)[0-9.eE+-]+", r"\g<1>1.0", text)
    z_alpha = [l["alpha_v"] for l in weighted["safety"]["velocity_limits"] if l["axis"] == "z"]
    z_limit = [l["upper"] for l in weighted["safety"]["velocity_limits"] if l["axis"] == "z"][0]
    z_pos_limit = [l["upper"] for l in weighted["safety"]["position_limits"] if l["axis"] == "z"][0]
    with tempfile.TemporaryDirectory() as tmp:
        runs = {}
        for name, cfg in ((f"weighted (z alpha_v = {z_alpha[0]:g})", text),
                          ("uniform (every alpha_v = 1)", uniform_text)):
            path = os.path.join(tmp, "config.yaml")
            with open(path, "w") as f:
                f.write(cfg)
            runs[name] = run(tool, path, os.path.join(tmp, "run.csv"))

    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for name, c in runs.items():
        sel = [i for i, t in enumerate(c["t"]) if t >= 18.0]
        t = [c["t"][i] for i in sel]
        axes[0].plot(t, [c["q_z"][i] for i in sel], label=name)
        axes[1].plot(t, [c["qd_z"][i] for i in sel], label=name)
        axes[2].plot(t, [c["h_vel"][i] for i in sel], label=name)
    axes[0].axhline(z_pos_limit, color="r", lw=0.8, label="limit")
    axes[1].axhline(z_limit, color="r", lw=0.8, label="limit")
    axes[0].set_ylabel("z (m)")
    axes[1].set_ylabel("dz/dt (m/s)")
    axes[2].set_ylabel("h_vel composed (m/s)")
    axes[2].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Fig. 4 equivalent: uniform vs weighted alpha on z (paper scenario, EKF in the loop)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    for name, c in runs.items():
        print(f"{name}: max dz/dt {max(c['qd_z']):.5f} m/s (limit {z_limit}), "
              f"max z {max(c['q_z']):.4f} m")


if __name__ == "__main__":
    main()
