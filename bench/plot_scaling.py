#!/usr/bin/python3
"""Plots of the scaling benchmark (bench/scaling.cc).

Usage: /usr/bin/python3 bench/plot_scaling.py [RESULTS_DIR]

Reads RESULTS_DIR/scaling.csv (default RESULTS_DIR = bench/results) and
writes RESULTS_DIR/scaling.png, 2 x 3 panels:
  top:    total time versus n (log-log; every family and method, with
          dotted slope-1 guides), Ceres time / SE-Sync time versus n, peak
          RSS versus n;
  bottom: SE-Sync's time per stage versus n, one panel per family (city2d,
          city3d, cube).
"""

import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FAMILIES = ("city2d", "city3d", "cube")
FAMILY_COLOR = {"city2d": "tab:blue", "city3d": "tab:orange",
                "cube": "tab:green"}
METHOD_STYLE = {"SE-Sync": dict(marker="o", linestyle="-"),
                "PDL-GN": dict(marker="s", linestyle="--"),
                "LM": dict(marker="^", linestyle=":")}
STAGES = (("data_s", "data matrices"), ("initialization_s", "chordal init"),
          ("optimization_s", "optimization"),
          ("verification_s", "verification"), ("rounding_s", "rounding"))


def num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return float("nan")


def series(rows, family, method, key):
    pts = sorted((num(r["n"]), num(r[key])) for r in rows
                 if r["family"] == family and r["method"] == method)
    return [p for p in pts if p[0] > 0 and p[1] > 0 and not math.isnan(p[1])]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
    with open(os.path.join(out, "scaling.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    time_ax, ratio_ax, rss_ax = axes[0]
    for family in FAMILIES:
        color = FAMILY_COLOR[family]
        for method, style in METHOD_STYLE.items():
            pts = series(rows, family, method, "time_s")
            if pts:
                time_ax.loglog([p[0] for p in pts], [p[1] for p in pts],
                               color=color, label=f"{family} {method}",
                               **style)
            if method != "SE-Sync":
                pts = series(rows, family, method, "time_ratio_to_sesync")
                if pts:
                    ratio_ax.semilogx([p[0] for p in pts],
                                      [p[1] for p in pts], color=color,
                                      label=f"{family} {method} / SE-Sync",
                                      **style)
            if method in ("SE-Sync", "PDL-GN"):
                pts = series(rows, family, method, "peak_rss_mib")
                if pts:
                    rss_ax.loglog([p[0] for p in pts], [p[1] for p in pts],
                                  color=color, label=f"{family} {method}",
                                  **style)
    # Slope-1 guides through the smallest SE-Sync point of each family.
    for family in FAMILIES:
        pts = series(rows, family, "SE-Sync", "time_s")
        if len(pts) >= 2:
            n0, t0 = pts[0]
            n1 = pts[-1][0]
            time_ax.loglog([n0, n1], [t0, t0 * n1 / n0], color="gray",
                           linewidth=0.7, linestyle=":")
    time_ax.set_title("total time (dotted: slope 1)")
    time_ax.set_ylabel("time [s]")
    ratio_ax.axhline(1, color="gray", linewidth=0.8)
    ratio_ax.set_title("Ceres time / SE-Sync time (> 1: SE-Sync faster)")
    ratio_ax.set_ylabel("ratio")
    rss_ax.set_title("peak RSS of the run's process")
    rss_ax.set_ylabel("MiB")
    for ax in axes[0]:
        ax.set_xlabel("number of poses n")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)

    for ax, family in zip(axes[1], FAMILIES):
        for key, label in STAGES:
            pts = series(rows, family, "SE-Sync", key)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts],
                          marker="o", label=label)
        total = series(rows, family, "SE-Sync", "time_s")
        if total:
            ax.loglog([p[0] for p in total], [p[1] for p in total],
                      color="black", linewidth=2, label="total")
        ax.set_title(f"SE-Sync stages: {family}")
        ax.set_xlabel("number of poses n")
        ax.set_ylabel("time [s]")
        ax.grid(True, which="both", alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=7)
    fig.suptitle("Scaling: SE-Sync vs Ceres from the chordal initialization "
                 "(bench/scaling.cc)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scaling.png"), dpi=70)


if __name__ == "__main__":
    main()
