"""SE-Sync certifiably correct pose-graph optimization on numpy arrays.

    import ceres_sesync as cs

    g = cs.read_g2o("intel.g2o")          # ValueError("intel.g2o:12: ...") on bad input
    r = cs.solve(g)                        # keywords: SolverOptions fields
    print(r.status, r.objective, r.lower_bound, r.relative_suboptimality_bound)
    r.rotations, r.translations            # (n, d, d) and (n, d), graph pose order
    r.landmarks                            # (L, d) landmark positions (L may be 0)
    c = cs.certify(g, rotations, translations)   # any solution, e.g. from Ceres
    c = cs.certify(g, rotations, translations, landmarks)   # with landmarks
    cs.write_g2o("out.g2o", g, r.rotations, r.translations)

The C++ headers (ceres_sesync/*.h) document every option and summary field;
the Python names are the C++ names. Solves and certificates run without the
GIL (other Python threads keep running) and can be stopped with Ctrl-C
(KeyboardInterrupt) when run from the main thread.
"""

import errno as _errno
import os as _os

from . import _ceres_sesync as _core
from ._ceres_sesync import (
    Certificate,
    CertifyOptions,
    CityOptions,
    ComponentsResult,
    ComponentsSummary,
    CubeOptions,
    G2oReadOptions,
    G2oReadSummary,
    Initialization,
    LandmarkGraphOptions,
    LocalSolver,
    Measurements,
    PoseGraph,
    PoseGraphComponent,
    Preconditioner,
    ProofArithmetic,
    RobustResult,
    RobustSolverOptions,
    RobustSolverSummary,
    SolveResult,
    SolverOptions,
    SolverProgress,
    SolverSummary,
    keep_freed_memory,
)

__version__ = _core.__version__

__all__ = [
    "Certificate",
    "CertifyOptions",
    "CityOptions",
    "ComponentsResult",
    "ComponentsSummary",
    "CubeOptions",
    "G2oReadOptions",
    "G2oReadSummary",
    "Initialization",
    "LandmarkGraphOptions",
    "LocalSolver",
    "Measurements",
    "PoseGraph",
    "PoseGraphComponent",
    "Preconditioner",
    "ProofArithmetic",
    "RobustResult",
    "RobustSolverOptions",
    "RobustSolverSummary",
    "SolveResult",
    "SolverOptions",
    "SolverProgress",
    "SolverSummary",
    "certify",
    "evaluate_objective",
    "generate_city",
    "generate_cube",
    "generate_landmarks",
    "keep_freed_memory",
    "read_g2o",
    "read_g2o_poses",
    "read_g2o_solution",
    "solve",
    "solve_components",
    "write_g2o",
    "write_g2o_poses",
    "write_tum",
]


def _options(cls, keywords, where):
    options = cls()
    _core._apply_keywords(options, keywords, where)
    return options


def _input_path(path):
    path = _os.fspath(path)
    if not _os.path.exists(path):
        raise FileNotFoundError(_errno.ENOENT, _os.strerror(_errno.ENOENT), path)
    if _os.path.isdir(path):
        raise IsADirectoryError(_errno.EISDIR, _os.strerror(_errno.EISDIR), path)
    return path


# ---- reading and writing -----------------------------------------------------


def read_g2o(path, *, return_summary=False, **options):
    """Reads a g2o pose graph (EDGE_SE2, EDGE_SE3:QUAT, VERTEX_*, FIX, TORO).

    Keyword options are G2oReadOptions fields: skip_unsupported_tags=True
    skips (and counts) landmark/prior lines instead of rejecting the file;
    allow_disconnected=True accepts a disconnected graph (solve it with
    solve_components()). Returns the PoseGraph, or (graph, G2oReadSummary)
    with return_summary=True.

    Raises FileNotFoundError for a missing file and ValueError("PATH:LINE:
    what is wrong") for bad contents (see ceres_sesync/g2o_io.h).
    """
    path = _input_path(path)
    options = _options(G2oReadOptions, options, "read_g2o")
    graph, summary = _core._read_g2o(path, options)
    return (graph, summary) if return_summary else graph


def read_g2o_poses(path, graph):
    """Reads the VERTEX lines of a poses file (e.g. another optimizer's output),
    matched by vertex id to the poses of `graph`.

    Returns (rotations (n, d, d), translations (n, d)) in the graph's pose
    order. Raises ValueError("PATH:LINE: ...") for unknown or missing ids,
    wrong dimensions or malformed lines.
    """
    return _core._read_g2o_poses(_input_path(path), graph)


def read_g2o_solution(path, graph):
    """As read_g2o_poses(), and also the landmark VERTEX lines (VERTEX_XY /
    VERTEX_TRACKXYZ), matched by id to the landmarks of `graph`.

    Returns (rotations (n, d, d), translations (n, d), landmarks (L, d)).
    """
    return _core._read_g2o_solution(_input_path(path), graph)


def write_g2o(path, graph, rotations=None, translations=None, landmarks=None):
    """Writes the whole graph (edges with isotropic information reproducing
    kappa and tau, landmark measurements, priors, FIX) as g2o, with VERTEX
    lines for the given poses and landmark positions ((L, d)) if any.
    Atomic: on failure (OSError) no partial file is left."""
    _core._write_g2o(_os.fspath(path), graph, rotations, translations, landmarks)


def write_g2o_poses(path, graph, rotations, translations, landmarks=None):
    """Writes only VERTEX lines (original ids) for the poses, and for the
    landmark positions ((L, d)) if given. Atomic."""
    _core._write_g2o_poses(_os.fspath(path), graph, rotations, translations, landmarks)


def write_tum(path, graph, rotations, translations):
    """Writes a TUM trajectory ("timestamp tx ty tz qx qy qz qw" per pose,
    timestamp = vertex id; 2D poses with z = 0). Atomic."""
    _core._write_tum(_os.fspath(path), graph, rotations, translations)


# ---- graphs ------------------------------------------------------------------


def _from_measurements(
    d,
    i,
    j,
    R,
    t,
    kappa,
    tau,
    *,
    num_poses=None,
    vertex_ids=None,
    initial_rotations=None,
    initial_translations=None,
    fixed_pose=None,
    allow_disconnected=False,
):
    """A PoseGraph from measurement arrays (m measurements, dimension d):

      i, j   (m,) integer pose indices: measurement k relates pose i[k] to j[k]
      R      (m, d, d) relative rotations, R[k] ~ R_i^T R_j (in SO(d))
      t      (m, d) relative translations, t[k] ~ R_i^T (t_j - t_i)
      kappa  (m,) rotational precisions (> 0)
      tau    (m,) translational precisions (> 0)

    num_poses defaults to max(i, j) + 1; vertex_ids (n,) to 0..n-1;
    initial_rotations (n, d, d) / initial_translations (n, d) are the graph's
    initial poses (solve(..., initialization="vertices")); fixed_pose the index
    of the gauge pose (FIX). The objective is eq. (12) of the SE-Sync paper:
    sum kappa ||R_j - R_i R[k]||_F^2 + tau ||t_j - t_i - R_i t[k]||^2.

    Raises ValueError for wrong shapes or invalid values (naming the
    measurement), and for a disconnected graph unless allow_disconnected.
    """
    return _core._pose_graph_from_measurements(
        d,
        i,
        j,
        R,
        t,
        kappa,
        tau,
        num_poses,
        vertex_ids,
        initial_rotations,
        initial_translations,
        fixed_pose,
        allow_disconnected,
    )


PoseGraph.from_measurements = staticmethod(_from_measurements)
PoseGraph.__repr__ = lambda g: (
    f"PoseGraph(dimension={g.dimension}, num_poses={g.num_poses}, "
    f"num_measurements={g.num_measurements})"
)
Measurements.__repr__ = lambda s: f"<Measurements: {len(s)} measurements>"
PoseGraphComponent.__repr__ = lambda c: f"<PoseGraphComponent: {c.graph!r}>"


def evaluate_objective(graph, rotations, translations, landmarks=None):
    """F(x) of eq. (12) at the given poses ((n, d, d) and (n, d) arrays), plus
    the landmark and prior terms (landmarks: (L, d), required when the graph
    has landmarks)."""
    return _core._evaluate_objective(graph, rotations, translations, landmarks)


def generate_cube(**options):
    """The synthetic cube benchmark of the SE-Sync paper (Section 6.1).

    Keyword options are CubeOptions fields (dimension=3, side=10,
    loop_closure_probability=0.1, loop_closure_radius=1, kappa=16.67, tau=75,
    spacing=1, seed=0; see ceres_sesync/cube_generator.h). Returns (graph,
    true_rotations, true_translations).
    """
    return _core._generate_cube(_options(CubeOptions, options, "generate_cube"))


def generate_city(**options):
    """A large Manhattan-style random-walk map for scaling studies.

    Keyword options are CityOptions fields (dimension=2, num_poses=10000,
    loop_closure_probability=0.3, kappa=100, tau=100, seed=0, ...; see
    ceres_sesync/city_generator.h). Returns (graph, true_rotations,
    true_translations).
    """
    return _core._generate_city(_options(CityOptions, options, "generate_city"))


def generate_landmarks(preset="manhattan", **options):
    """A landmark-SLAM graph: a Manhattan walk observing random point
    landmarks within a sensor range, optional GPS-like position priors
    (gps_interval) and a start prior (see ceres_sesync/landmark_generator.h).

    preset="victoria" starts from the Victoria-Park-like dense preset (2000
    poses, ~30 landmarks per pose); keyword options are LandmarkGraphOptions
    fields and override the preset's. Returns (graph, true_rotations,
    true_translations, true_landmarks).
    """
    if preset == "victoria":
        base = _core._victoria_park_like_options()
    elif preset == "manhattan":
        base = LandmarkGraphOptions()
    else:
        raise ValueError(f"preset '{preset}' is not one of 'manhattan', 'victoria'")
    _core._apply_keywords(base, options, "generate_landmarks")
    return _core._generate_landmarks(base)


# ---- solving and certifying --------------------------------------------------


def solve(graph, initial_rotations=None, *, robust=False, **options):
    """Solves the pose graph with SE-Sync and certifies the result.

    Keyword options are SolverOptions fields, e.g. max_rank=10,
    initialization="chordal"|"random"|"vertices", num_threads=0 (all cores),
    max_time_s=0 (none), proof_arithmetic="automatic"|"double"|"double_double",
    progress=callable receiving a SolverProgress at every stage and iteration. An unknown keyword raises
    TypeError. initial_rotations ((n, d, d)) starts the staircase from those
    rotations instead.

    Returns a SolveResult: every SolverSummary field (status, objective,
    lower_bound, relative_suboptimality_bound, levels, times, ...), certified,
    rotations (n, d, d), translations (n, d), landmarks (L, d: the landmark
    positions, L = 0 without landmarks), and summary (the full report). With
    priors the solution is in their world frame.

    robust=True: the outlier-robust solve (GNC with truncated least squares
    around SE-Sync, robust_solver.h). Keywords may then also be
    RobustSolverOptions fields (inlier_threshold, inlier_probability,
    known_inliers="odometry"|"none", gnc_threshold_fractions, ...). Returns a
    RobustResult: every RobustSolverSummary field (status, edges,
    outlier_edges as an array, inlier_summary, history, ...), weights and
    inliers (one per measurement), rotations and translations of the problem
    restricted to the accepted measurements, and its objective, lower_bound,
    relative_suboptimality_bound; certified means that problem's optimum is
    certified (not that the TLS problem is solved globally).
    """
    if not robust:
        options = _options(SolverOptions, options, "solve")
        return _core._solve(graph, options, initial_rotations)
    if initial_rotations is not None:
        raise TypeError("solve(robust=True) does not take initial_rotations")
    robust_fields = set(RobustSolverOptions._fields) - {"solver_options"}
    robust_keywords = {k: v for k, v in options.items() if k in robust_fields}
    solver_keywords = {k: v for k, v in options.items() if k not in robust_fields}
    robust_options = _options(RobustSolverOptions, robust_keywords, "solve")
    robust_options.solver_options = _options(SolverOptions, solver_keywords, "solve")
    return _core._solve_robust(graph, robust_options)


def solve_components(graph, **options):
    """Solves each connected component of a (possibly disconnected) graph on
    its own (poses and landmarks linked by measurements; all priors are in
    one component), in its own gauge (its first pose, or its FIX pose,
    fixed; the component with the priors in the world frame, gauge_vertex_id
    -1).

    Keyword options as for solve(). Returns a ComponentsResult: components
    (each with poses, landmarks, gauge_vertex_id and its SolverSummary), the
    sums objective / lower_bound / ..., status, certified, and rotations,
    translations and landmarks of the whole graph.
    """
    options = _options(SolverOptions, options, "solve_components")
    return _core._solve_by_component(graph, options)


def certify(graph, rotations, translations, landmarks=None, **options):
    """Certifies any solution (rotations (n, d, d), translations (n, d), and
    landmarks (L, d) when the graph has landmarks).

    Keyword options are CertifyOptions fields, e.g.
    max_relative_suboptimality=1e-3, improve_if_not_certified=False,
    solver_options=SolverOptions or dict. Returns a Certificate: certified,
    objective, lower_bound (a proven lower bound on the optimum, valid whether
    or not certified), relative_suboptimality_bound,
    negative_curvature_direction (None or a witness of non-optimality),
    improved_poses, improved_landmarks, ... and summary (the full report).

    Raises ValueError for arrays of the wrong shape or non-finite values.
    """
    options = _options(CertifyOptions, options, "certify")
    return _core._certify(graph, rotations, translations, landmarks, options)


# ---- generic helpers on every bound struct -------------------------------------


def _value(v):
    if hasattr(v, "_fields"):
        return _as_dict(v)
    if isinstance(v, list):
        return [_value(x) for x in v]
    if hasattr(type(v), "__members__"):  # A bound enum.
        return v.name
    return v


def _as_dict(self):
    """The fields as a dict (nested structs as dicts, enums as names)."""
    return {name: _value(getattr(self, name)) for name in self._fields}


def _options_repr(self):
    fields = ", ".join(f"{name}={_value(getattr(self, name))!r}" for name in self._fields)
    return f"{type(self).__name__}({fields})"


for _cls in (
    Certificate,
    CertifyOptions,
    CityOptions,
    ComponentsResult,
    ComponentsSummary,
    ComponentsSummary.Component,
    CubeOptions,
    G2oReadOptions,
    G2oReadSummary,
    LandmarkGraphOptions,
    RobustResult,
    RobustSolverOptions,
    RobustSolverSummary,
    RobustSolverSummary.Edge,
    RobustSolverSummary.Iteration,
    RobustSolverSummary.Run,
    SolveResult,
    SolverOptions,
    SolverProgress,
    SolverSummary,
    SolverSummary.Level,
):
    _cls.as_dict = _as_dict
for _cls in (
    CertifyOptions,
    CityOptions,
    CubeOptions,
    G2oReadOptions,
    LandmarkGraphOptions,
    RobustSolverOptions,
    SolverOptions,
    SolverProgress,
):
    _cls.__repr__ = _options_repr
for _cls in (SolverSummary, ComponentsSummary, RobustSolverSummary):
    _cls.__repr__ = lambda self: f"<{type(self).__name__}: {self.brief_report}>"
Certificate.__repr__ = lambda self: f"<{self.brief_report}>"
SolverSummary.Level.__repr__ = lambda l: (
    f"<Level rank {l.rank}: {l.iterations} iterations, F(Y) {l.sdp_value:.10g}, "
    f"{'certified' if l.certified else l.termination}>"
)
ComponentsSummary.Component.__repr__ = lambda c: (
    f"<Component: {len(c.poses)} poses, gauge vertex {c.gauge_vertex_id}, {c.summary.status}>"
)
del _cls
