#!/usr/bin/python3
"""Draws the platform's legs and joints at one or more poses, from the model
tool's output (so the picture shows exactly the model the stack uses).

Usage: tools/plots/platform_geometry.py OUT.png
Run with Debian's /usr/bin/python3 (python3-matplotlib).
"""
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(os.environ.get("STEWART_BUILD_DIR", os.path.join(ROOT, "build")),
                    "tools", "stewart_model_tool")

POSES = [("home q0", [0, 0, 0.4, 0, 0, 0], "tab:blue"),
         ("x limit 0.11 m", [0.11, 0, 0.4, 0, 0, 0], "tab:orange"),
         ("z limit 0.51 m", [0, 0, 0.51, 0, 0, 0], "tab:green")]


def evaluate(q):
    return json.loads(subprocess.check_output([TOOL, "--q"] + [str(v) for v in q]))


def ring(points):
    return [p[0] for p in points] + [points[0][0]], [p[1] for p in points] + [points[0][1]], \
           [p[2] for p in points] + [points[0][2]]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "platform.png"
    fig = plt.figure(figsize=(11, 5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    side = fig.add_subplot(1, 2, 2)
    for label, q, color in POSES:
        r = evaluate(q)
        base, top = r["base_joints_m"], r["platform_joints_m"]
        ax.plot(*ring(base), color="k", lw=1)
        ax.plot(*ring(top), color=color, lw=2, label=label)
        for b, a in zip(base, top):
            ax.plot([b[0], a[0]], [b[1], a[1]], [b[2], a[2]], color=color, lw=1)
        side.plot([p[0] for p in top] + [top[0][0]], [p[2] for p in top] + [top[0][2]], "o-",
                  color=color, ms=3, label=f"{label}: legs {min(r['leg_length_m']):.3f}-"
                                               f"{max(r['leg_length_m']):.3f} m")
        for b, a in zip(base, top):
            side.plot([b[0], a[0]], [b[2], a[2]], color=color, lw=0.8)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title("Stewart platform model (config/platform.yaml)")
    ax.legend(loc="upper left", fontsize=8)
    side.axhline(0.51, color="tab:red", ls="--", lw=1, label="z limit (paper)")
    side.set_xlabel("x (m)")
    side.set_ylabel("z (m)")
    side.set_aspect("equal")
    side.set_title("side view (x-z)")
    side.legend(fontsize=7, loc="lower center")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
