#!/usr/bin/python3
"""Trajectory plots of solved pose graphs (like Figs. 4-5 of Rosen et al.).

Usage:
  /usr/bin/python3 bench/plot_trajectory.py POSES_DIR [OUT_DIR]
      [--datasets intel,manhattan,...] [--compare manhattan]

POSES_DIR holds the g2o VERTEX files that `bench --poses_dir POSES_DIR`
writes: DATASET_sesync.g2o (the SE-Sync solution) and DATASET_initial.g2o
(the file's own VERTEX guess, or the odometry composition when the file has
none). Writes to OUT_DIR (default bench/results):
  trajectories.png      one panel per dataset: the SE-Sync solution, poses
                        joined in file order (top view for 2D; a 3D
                        projection for 3D);
  trajectory_compare_DATASET.png   initial guess next to the SE-Sync solution.
"""

import argparse
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DEFAULT_DATASETS = ("intel,manhattan,city10000,ais2klinik,sphere2500,"
                    "torus3D,cubicle,parking-garage,CSAIL")


def read_vertices(path):
    """Returns (dimension, list of (x, y, z)) from g2o VERTEX lines."""
    points, dim = [], 0
    with open(path) as f:
        for line in f:
            tok = line.split()
            if not tok:
                continue
            if tok[0] == "VERTEX_SE2":
                dim = 2
                points.append((float(tok[2]), float(tok[3]), 0.0))
            elif tok[0] == "VERTEX_SE3:QUAT":
                dim = 3
                points.append((float(tok[2]), float(tok[3]), float(tok[4])))
    return dim, points


def draw(ax, dim, pts, title):
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    if dim == 3:
        zs = [p[2] for p in pts]
        ax.plot(xs, ys, zs, linewidth=0.4, color="tab:blue")
        ax.set_xticklabels([])
        ax.set_yticklabels([])
        ax.set_zticklabels([])
        # Equal aspect on all three axes.
        spans = [max(v) - min(v) for v in (xs, ys, zs)]
        ax.set_box_aspect([max(s, 1e-9) for s in spans])
    else:
        ax.plot(xs, ys, linewidth=0.4, color="tab:blue")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xticks([])
        ax.set_yticks([])
    ax.set_title(title, fontsize=9)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("poses_dir")
    parser.add_argument("out_dir", nargs="?", default="bench/results")
    parser.add_argument("--datasets", default=DEFAULT_DATASETS)
    parser.add_argument("--compare", default="manhattan")
    args = parser.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)

    found = []
    for name in args.datasets.split(","):
        path = os.path.join(args.poses_dir, name + "_sesync.g2o")
        if os.path.exists(path):
            found.append((name, *read_vertices(path)))
    if found:
        cols = min(3, len(found))
        rows = math.ceil(len(found) / cols)
        fig = plt.figure(figsize=(4 * cols, 3.6 * rows))
        for k, (name, dim, pts) in enumerate(found):
            ax = fig.add_subplot(rows, cols, k + 1,
                                 projection="3d" if dim == 3 else None)
            draw(ax, dim, pts, f"{name} (SE-Sync, n = {len(pts)})")
        fig.subplots_adjust(left=0.02, right=0.98, bottom=0.02, top=0.95,
                            wspace=0.1, hspace=0.15)
        fig.savefig(os.path.join(args.out_dir, "trajectories.png"), dpi=60)
        plt.close(fig)

    name = args.compare
    init = os.path.join(args.poses_dir, name + "_initial.g2o")
    sol = os.path.join(args.poses_dir, name + "_sesync.g2o")
    if os.path.exists(init) and os.path.exists(sol):
        dim, p0 = read_vertices(init)
        _, p1 = read_vertices(sol)
        fig = plt.figure(figsize=(10, 4.6))
        for k, (pts, what) in enumerate(
                ((p0, "initial guess (file vertices / odometry)"),
                 (p1, "SE-Sync (certified optimum)"))):
            ax = fig.add_subplot(1, 2, k + 1,
                                 projection="3d" if dim == 3 else None)
            draw(ax, dim, pts, f"{name}: {what}")
        fig.subplots_adjust(left=0.02, right=0.98, bottom=0.02, top=0.92,
                            wspace=0.1)
        fig.savefig(os.path.join(args.out_dir,
                                 f"trajectory_compare_{name}.png"), dpi=70)
        plt.close(fig)
    print(f"plotted {len(found)} datasets from {args.poses_dir}")


if __name__ == "__main__":
    main()
