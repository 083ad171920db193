#!/usr/bin/python3
"""Plots of a campaign folder (docs/campaign.md): the CDF of each run's worst
position and velocity margin, and the worst margin against every sampled
parameter, so a reader sees which parameter breaks safety.

usage: /usr/bin/python3 tools/plots/campaign_plots.py DIR
writes DIR/margin_cdf.png and DIR/margin_vs_parameters.png
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def is_velocity(limit):
    name = limit.split("_")[0]
    return name.endswith("d")


def main(folder):
    with open(f"{folder}/runs.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("campaign_plots: no runs", file=sys.stderr)
        return 1
    header = list(rows[0].keys())
    margins = [c for c in header if c.endswith("_margin")]
    first_limit = min(header.index(c) for c in header if c.endswith("_excess"))
    parameters = header[header.index("scenario") + 1:first_limit]

    def worst(row, velocity):
        values = [float(row[c]) for c in margins if is_velocity(c) == velocity and row[c] != ""]
        values = [v for v in values if not math.isnan(v)]
        return min(values) * 1e3 if values else float("nan")

    groups = [("position", False, "mm"), ("velocity", True, "mm/s")]
    worst_by_group = {g: [worst(r, v) for r in rows] for g, v, _ in groups}

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, (group, _, unit) in zip(axes, groups):
        values = sorted(v for v in worst_by_group[group] if not math.isnan(v))
        n = len(values)
        ax.step(values, [(i + 1) / n for i in range(n)], where="post")
        # Margins run from metres outside to millimetres inside: linear near
        # zero (the tolerance), logarithmic beyond.
        ax.set_xscale("symlog", linthresh=1.0)
        ax.axvline(0.0, color="k", lw=0.8)
        ax.axvline(-1.0, color="r", lw=0.8, ls="--", label="tolerance (-1)")
        ax.set_xlabel(f"worst {group} margin over the run ({unit}); < 0: limit exceeded")
        ax.set_ylabel("fraction of runs")
        ax.legend(loc="lower right")
        ax.grid(alpha=0.3)
    fig.suptitle(f"{len(rows)} runs: CDF of the worst margin on ground truth")
    fig.tight_layout()
    fig.savefig(f"{folder}/margin_cdf.png", dpi=110)

    if parameters:
        cols = min(4, len(parameters))
        nrows = math.ceil(len(parameters) / cols)
        fig, axes = plt.subplots(nrows, cols, figsize=(3.6 * cols, 2.8 * nrows), squeeze=False)
        for k, p in enumerate(parameters):
            ax = axes[k // cols][k % cols]
            x = [float(r[p]) if r[p] != "" else float("nan") for r in rows]
            for group, _, unit in groups:
                ax.scatter(x, worst_by_group[group], s=4, label=f"{group} ({unit})")
            ax.axhline(0.0, color="k", lw=0.8)
            ax.set_yscale("symlog", linthresh=1.0)
            ax.set_xlabel(p, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
            if k == 0:
                ax.set_ylabel("worst margin")
                ax.legend(fontsize=7)
        for k in range(len(parameters), nrows * cols):
            axes[k // cols][k % cols].axis("off")
        fig.suptitle("worst margin against each sampled parameter")
        fig.tight_layout()
        fig.savefig(f"{folder}/margin_vs_parameters.png", dpi=110)
    print(f"plots: {folder}/margin_cdf.png" +
          (f", {folder}/margin_vs_parameters.png" if parameters else ""))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
