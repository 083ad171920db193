#!/usr/bin/python3
"""Paper Fig. 3: the true minimum of three barrier functions against the
Log-Sum-Exp approximation and the alpha-weighted LSE (paper eqs. 28, 33),

    h_c = -(1/k) ln sum_i exp(-k alpha_i h_i),

for k = 1, 2, 5, 10 and alpha = (1.2, 1, 0.8). The paper does not give its
three functions; these are three smooth barriers whose minimum switches
twice over the range, which is what the figure illustrates.

Usage: tools/plots/fig3_lse.py OUT.png    (Debian's /usr/bin/python3)
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ALPHAS = np.array([1.2, 1.0, 0.8])
KS = [1, 2, 5, 10]


def barriers(x):
    return np.stack([2.0 - 0.3 * x, 0.15 * (x - 5.0) ** 2 + 0.3, 0.25 * x - 0.2])


def lse(h, k, alpha):
    """Stable alpha-weighted LSE: shifted by the minimum of alpha_i h_i."""
    a = alpha[:, None] * h
    m = a.min(axis=0)
    return m - np.log(np.exp(-k * (a - m)).sum(axis=0)) / k


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "fig3_lse.png"
    x = np.linspace(0.0, 10.0, 801)
    h = barriers(x)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, alpha, title in ((axes[0], np.ones(3), "original LSE (alpha = 1)"),
                             (axes[1], ALPHAS, "alpha-weighted LSE (alpha = 1.2, 1, 0.8)")):
        for i in range(3):
            ax.plot(x, h[i], color="0.75", lw=1, ls=":")
        ax.plot(x, h.min(axis=0), color="k", lw=2.2, label="true min h_i")
        if alpha is ALPHAS:
            ax.plot(x, (alpha[:, None] * h).min(axis=0), color="k", lw=1.2, ls="--",
                    label="min alpha_i h_i")
        for k in KS:
            ax.plot(x, lse(h, k, alpha), lw=1.3, label=f"k = {k}")
        ax.set_title(title)
        ax.set_xlabel("x")
        ax.set_ylim(-2.5, 2.5)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right")
    axes[0].set_ylabel("h")
    fig.suptitle("Fig. 3 equivalent: smooth minimum of three barriers "
                 "(min - ln(N)/k <= h_c <= min)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
