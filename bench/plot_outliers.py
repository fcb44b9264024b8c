#!/usr/bin/python3
"""Plots of the outlier benchmark (bench/outliers.cc) against the fraction.

  plot_outliers.py DIR [--name outliers]

reads DIR/NAME.csv and writes DIR/NAME_random.png and DIR/NAME_clustered.png
(a mode without runs is skipped): per method, over every dataset and seed
at a fraction, the success rate (precision and recall >= 0.99 and clean
objective gap <= 1e-6), the worst precision and recall, and the medians of
the max rotation error, the clean objective gap and the time.
"""

import argparse
import csv
import math
import os
import statistics
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "sesync": ("SE-Sync (plain)", "tab:gray", "o"),
    "gnc": ("SE-Sync GNC-TLS", "tab:red", "s"),
    "lm-huber-chordal": ("LM Huber (chordal)", "tab:blue", "^"),
    "lm-cauchy-chordal": ("LM Cauchy (chordal)", "tab:green", "v"),
    "lm-huber-odometry": ("LM Huber (odometry)", "tab:cyan", "<"),
    "lm-cauchy-odometry": ("LM Cauchy (odometry)", "tab:olive", ">"),
}


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("dir")
    parser.add_argument("--name", default="outliers")
    args = parser.parse_args()
    with open(os.path.join(args.dir, args.name + ".csv")) as f:
        rows = list(csv.DictReader(f))
    for mode in ("random", "clustered"):
        runs = [r for r in rows if r["mode"] == mode]
        if not runs:
            continue
        by = defaultdict(list)
        for r in runs:
            by[(r["method"], float(r["fraction"]))].append(r)
        methods = [m for m in STYLE if any(k[0] == m for k in by)]
        panels = [
            ("success rate", lambda rs: statistics.mean(
                r["success"] == "1" for r in rs), "linear"),
            ("min precision", lambda rs: min(
                0 if math.isnan(number(r["precision"])) else
                number(r["precision"]) for r in rs), "linear"),
            ("min recall", lambda rs: min(
                0 if math.isnan(number(r["recall"])) else
                number(r["recall"]) for r in rs), "linear"),
            ("median max rotation error [deg]", lambda rs: median(
                rs, "max_rotation_error_deg"), "log"),
            ("median clean objective gap", lambda rs: median(
                rs, "clean_gap", floor=1e-16), "log"),
            ("median time [s]", lambda rs: median(rs, "time_s"), "log"),
        ]
        fig, axes = plt.subplots(2, 3, figsize=(14, 7.5))
        for ax, (title, stat, scale) in zip(axes.flat, panels):
            for method in methods:
                label, color, marker = STYLE[method]
                xs = sorted(f for (m, f) in by if m == method)
                ys = [stat(by[(method, f)]) for f in xs]
                ax.plot([100 * x for x in xs], ys, marker=marker, color=color,
                        label=label)
            ax.set_title(title)
            ax.set_xlabel("outliers [% of loop closures]")
            ax.set_yscale(scale)
            ax.grid(True, alpha=0.3)
        axes.flat[0].legend(fontsize=8)
        datasets = sorted({r["dataset"] for r in runs})
        seeds = len({r["seed"] for r in runs})
        fig.suptitle("%s outliers: %s (%d seeds)" %
                     (mode, ", ".join(datasets), seeds))
        fig.tight_layout()
        out = os.path.join(args.dir, "%s_%s.png" % (args.name, mode))
        fig.savefig(out, dpi=110)
        print("wrote", out)


def median(rows, key, floor=None):
    values = [number(r[key]) for r in rows]
    values = [v for v in values if not math.isnan(v)]
    if not values:
        return math.nan
    m = statistics.median(values)
    return max(m, floor) if floor is not None else m


if __name__ == "__main__":
    main()
