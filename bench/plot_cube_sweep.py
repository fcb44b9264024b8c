#!/usr/bin/python3
"""Figure-3-style plots of the cube experiments (Rosen et al., IJRR 2019).

Usage: /usr/bin/python3 bench/plot_cube_sweep.py [RESULTS_DIR]

Reads RESULTS_DIR/cube_sweep.csv and RESULTS_DIR/cube_scaling.csv (written
by the cube_sweep program; default RESULTS_DIR = bench/results) and writes
  cube_sweep.png    4 x 3 panels: rows = swept parameter (RMS rotation error,
                    RMS translation error, pLC, side s); columns = median
                    objective, median time, SE-Sync's relative suboptimality
                    bound (with the certified fraction annotated);
  cube_scaling.png  time versus n on log-log axes, SE-Sync and PDL-GN.
"""

import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROWS = [
    ("kappa", "RMS rotation error [deg]", lambda x: math.degrees(x)),
    ("tau", "RMS translation error [m]", lambda x: x),
    ("pLC", "loop-closure probability $p_{LC}$", lambda x: x),
    ("s", "side $s$ ($n = s^3$)", lambda x: x),
]
STYLE = {
    "SE-Sync": dict(color="tab:red", marker="o"),
    "PDL-GN/chordal": dict(color="tab:blue", marker="s"),
    "LM/chordal": dict(color="tab:green", marker="^"),
    "PDL-GN/odometry": dict(color="tab:purple", marker="x", linestyle="--"),
}


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return float("nan")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
    rows = read(os.path.join(out, "cube_sweep.csv"))
    fig, axes = plt.subplots(4, 3, figsize=(12, 12))
    for r, (sweep, label, xf) in enumerate(ROWS):
        data = [row for row in rows if row["sweep"] == sweep]
        for method, style in STYLE.items():
            pts = sorted(
                (xf(num(d["x"])), num(d["median_objective"]),
                 num(d["median_time_s"]))
                for d in data if d["method"] == method)
            if not pts:
                continue
            x = [p[0] for p in pts]
            axes[r][0].plot(x, [p[1] for p in pts], label=method, **style)
            axes[r][1].plot(x, [p[2] for p in pts], label=method, **style)
        ses = sorted((xf(num(d["x"])), num(d["median_rel_subopt_bound"]),
                      num(d["certified_fraction"]))
                     for d in data if d["method"] == "SE-Sync")
        if ses:
            x = [p[0] for p in ses]
            y = [max(p[1], 1e-16) for p in ses]
            axes[r][2].semilogy(x, y, **STYLE["SE-Sync"])
            for xi, yi, c in zip(x, y, [p[2] for p in ses]):
                axes[r][2].annotate(f"{c:.0%}", (xi, yi), fontsize=7,
                                    textcoords="offset points",
                                    xytext=(0, 5), ha="center")
            axes[r][2].axhline(1e-6, color="gray", linewidth=0.8,
                               linestyle=":")
        axes[r][0].set_ylabel("median objective F")
        axes[r][1].set_ylabel("median time [s]")
        axes[r][1].set_yscale("log")
        axes[r][2].set_ylabel("SE-Sync (F - LB) / LB")
        for c in range(3):
            axes[r][c].set_xlabel(label)
            axes[r][c].grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=8)
    axes[0][2].set_title("labels: fraction certified (bound <= 1e-6)",
                         fontsize=9)
    n_real = max((int(num(d["realizations"])) for d in rows), default=0)
    fig.suptitle(f"Cube experiments (median of {n_real} realizations; "
                 "defaults kappa 16.67, tau 75, pLC 0.1, s 10)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cube_sweep.png"), dpi=70)

    scaling_path = os.path.join(out, "cube_scaling.csv")
    if os.path.exists(scaling_path):
        runs = read(scaling_path)
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for method in ("SE-Sync", "PDL-GN/chordal"):
            pts = sorted((num(d["n"]), num(d["time_s"])) for d in runs
                         if d["method"] == method)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts],
                          label=method, **STYLE[method])
        ax.set_xlabel("number of poses n")
        ax.set_ylabel("time [s]")
        ax.set_title("Cube scaling (one realization per size)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "cube_scaling.png"), dpi=80)


if __name__ == "__main__":
    main()
