#!/usr/bin/env python3
"""Solve a pose graph with SE-Sync from Python and plot the trajectory.

    python3 solve_and_plot.py [GRAPH.g2o] [--output trajectory.png]

Reads GRAPH.g2o (default: the intel dataset of CERES_SESYNC_DATA_DIR, or,
when that is absent, a generated 3D cube), solves it, checks the certificate,
re-evaluates the objective with numpy from the returned arrays, and plots
the trajectory and loop closures with matplotlib (headless: Agg). Exits 1 if
the solution is not certified.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")  # headless: write a file, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ceres_sesync as cs  # noqa: E402


def load(path):
    if path:
        return cs.read_g2o(path), os.path.basename(path)
    data = os.path.join(os.environ.get("CERES_SESYNC_DATA_DIR", ""), "intel.g2o")
    if os.path.exists(data):
        return cs.read_g2o(data), "intel.g2o"
    graph, _, _ = cs.generate_cube(side=8, seed=0)
    return graph, "generated cube (side 8)"


def objective(graph, R, t):
    """Eq. (12) of the SE-Sync paper, in numpy."""
    m = graph.measurements
    rotation = R[m.j] - R[m.i] @ m.R
    translation = t[m.j] - t[m.i] - np.einsum("kab,kb->ka", R[m.i], m.t)
    return np.sum(m.kappa * np.sum(rotation**2, axis=(1, 2))) + np.sum(
        m.tau * np.sum(translation**2, axis=1)
    )


def plot(graph, t, title, path):
    m = graph.measurements
    loop = np.abs(m.j - m.i) != 1  # not odometry
    figure = plt.figure(figsize=(7, 6))
    if graph.dimension == 2:
        axes = figure.add_subplot()
        axes.set_aspect("equal")
    else:
        axes = figure.add_subplot(projection="3d")
    # All loop closures as one line broken by NaN rows.
    segments = np.full((3 * loop.sum(), graph.dimension), np.nan)
    segments[0::3], segments[1::3] = t[m.i[loop]], t[m.j[loop]]
    axes.plot(*segments.T, color="tab:orange", linewidth=0.3, alpha=0.6,
              label=f"{loop.sum()} loop closures")
    axes.plot(*t.T, color="tab:blue", linewidth=0.8, label="SE-Sync trajectory")
    axes.set_title(title)
    axes.legend(loc="best")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "graph", nargs="?", help="g2o file (default: intel.g2o or a generated cube)"
    )
    parser.add_argument("--output", default="solve_and_plot.png", help="PNG file to write")
    args = parser.parse_args()

    graph, name = load(args.graph)
    print(f"{name}: {graph}")
    result = cs.solve(graph)
    print(result.brief_report)

    # The arrays are in the graph's pose order: eq. (12) from numpy agrees.
    f = objective(graph, result.rotations, result.translations)
    print(f"objective from numpy: {f:.10g} (solver: {result.objective:.10g})")
    assert abs(f - result.objective) <= 1e-9 * result.objective

    title = (
        f"{name}: F = {result.objective:.6g}, "
        f"{'certified optimal' if result.certified else result.status} "
        f"(bound {result.relative_suboptimality_bound:.1e})"
    )
    plot(graph, result.translations, title, args.output)
    size = os.path.getsize(args.output)
    print(f"wrote {args.output} ({size} bytes)")
    if size < 1000:
        print("the plot is suspiciously small", file=sys.stderr)
        return 1
    return 0 if result.certified else 1


if __name__ == "__main__":
    sys.exit(main())
