// The extension module `ceres_sesync._ceres_sesync`: the C++ API on numpy
// arrays. The package's __init__.py (python/ceres_sesync/) wraps these
// functions with Python signatures and documentation; use that.
//
// Every option/summary struct is bound field by field in one function per
// struct (fields.h); keyword arguments map to those fields by name.

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ceres_sesync/certification.h"
#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/component_solver.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/process_memory.h"
#include "ceres_sesync/robust_solver.h"
#include "ceres_sesync/sesync_solver.h"
#include "glog/logging.h"
#include "python/src/arrays.h"
#include "python/src/fields.h"

namespace ceres_sesync::python {
namespace {

using Status = SolverSummary::Status;

// ---- results: the C++ summaries plus the numpy arrays of the poses --------

struct SolveResult : SolverSummary {
  py::object rotations, translations, landmarks;
};

struct ComponentsResult : ComponentsSummary {
  py::object rotations, translations, landmarks;
};

struct RobustResult : RobustSolverSummary {
  py::object rotations, translations, landmarks;
};

struct Measurements {
  py::object i, j, R, t, kappa, tau;
  py::ssize_t size = 0;
};

// ---- helpers ----------------------------------------------------------------

template <typename Int>
py::array_t<int64_t> IndexArray(const std::vector<Int>& values) {
  py::array_t<int64_t> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

// Enums accept their names as strings too: options.initialization =
// "random".
template <typename E>
void AcceptNames(py::enum_<E>& cls) {
  py::object type = cls;
  cls.def(py::init([type](const std::string& name) {
            py::dict members = type.attr("__members__");
            if (!members.contains(name)) {
              std::string names;
              for (auto item : members) {
                names += (names.empty() ? "'" : ", '") +
                         std::string(py::str(item.first)) + "'";
              }
              throw py::value_error("'" + name + "' is not one of " + names);
            }
            return members[py::str(name)].cast<E>();
          }),
          py::arg("name"));
  py::implicitly_convertible<py::str, E>();
}

// Options classes: T() and T(**fields).
template <typename T, typename Class>
void KeywordInit(Class& cls, const char* name) {
  cls.def(py::init([name](const py::kwargs& kwargs) {
    T value;
    {
      py::object view = py::cast(&value, py::return_value_policy::reference);
      ApplyKeywords(view, kwargs, name);
    }
    return value;
  }));
  cls.def("__copy__", [](const T& value) { return T(value); });
  cls.def("__deepcopy__",
          [](const T& value, const py::dict&) { return T(value); });
}

// Ctrl-C (KeyboardInterrupt) stops a solve run from the main thread: the
// progress hook checks for pending signals at most every 50 ms (the GIL is
// taken only then) and raises the exception through the solver. The user's
// own progress callback, if any, is called after.
void MakeInterruptible(SolverOptions* options) {
  py::module_ threading = py::module_::import("threading");
  const bool main_thread =
      threading.attr("current_thread")().is(threading.attr("main_thread")());
  if (!main_thread) return;
  using Clock = std::chrono::steady_clock;
  auto last = std::make_shared<Clock::time_point>(Clock::now());
  options->progress = [user = options->progress,
                       last](const SolverProgress& progress) {
    const auto now = Clock::now();
    if (now - *last >= std::chrono::milliseconds(50)) {
      *last = now;
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    if (user) user(progress);
  };
}

// ---- bindings ---------------------------------------------------------------

void BindEnums(py::module_& m) {
  using O = SolverOptions;
  py::enum_<O::Initialization> init(m, "Initialization",
                                    "SolverOptions::Initialization");
  init.value("chordal", O::Initialization::kChordal)
      .value("random", O::Initialization::kRandom)
      .value("vertices", O::Initialization::kVertices);
  AcceptNames(init);
  py::enum_<O::Preconditioner> pre(m, "Preconditioner",
                                   "SolverOptions::Preconditioner");
  pre.value("none", O::Preconditioner::kNone)
      .value("block_jacobi", O::Preconditioner::kBlockJacobi)
      .value("sparse_cholesky", O::Preconditioner::kSparseCholesky)
      .value("regularized_q", O::Preconditioner::kRegularizedQ)
      .value("automatic", O::Preconditioner::kAutomatic);
  AcceptNames(pre);
  py::enum_<O::LocalSolver> local(m, "LocalSolver",
                                  "SolverOptions::LocalSolver");
  local.value("trust_region", O::LocalSolver::kTrustRegion)
      .value("ceres_lbfgs", O::LocalSolver::kCeresLbfgs);
  AcceptNames(local);
  py::enum_<O::ProofArithmetic> proof(m, "ProofArithmetic",
                                      "SolverOptions::ProofArithmetic");
  proof.value("automatic", O::ProofArithmetic::kAutomatic)
      .value("double", O::ProofArithmetic::kDouble)
      .value("double_double", O::ProofArithmetic::kDoubleDouble);
  AcceptNames(proof);
}

void BindSolverProgress(py::module_& m) {
  using P = SolverProgress;
  py::class_<P> cls(m, "SolverProgress",
                    "What a progress callback receives (sesync_solver.h).");
  Fields(cls)
      .ro("stage", &P::stage)
      .ro("rank", &P::rank)
      .ro("iteration", &P::iteration)
      .ro("objective", &P::objective)
      .ro("gradient_norm", &P::gradient_norm)
      .ro("elapsed_s", &P::elapsed_s)
      .ro("component", &P::component)
      .ro("num_components", &P::num_components);
}

void BindSolverOptions(py::module_& m) {
  using O = SolverOptions;
  py::class_<O> cls(m, "SolverOptions",
                    "ceres_sesync::SolverOptions (see sesync_solver.h for "
                    "every field's meaning and default).");
  Fields(cls)
      .rw("initialization", &O::initialization)
      .rw("seed", &O::seed)
      .rw("initial_rank", &O::initial_rank)
      .rw("max_rank", &O::max_rank)
      .rw("preconditioner", &O::preconditioner)
      .rw("regularized_cholesky_max_condition",
          &O::regularized_cholesky_max_condition)
      .rw("local_solver", &O::local_solver)
      .rw("ceres_lbfgs_max_iterations", &O::ceres_lbfgs_max_iterations)
      .rw("ceres_lbfgs_gradient_tolerance", &O::ceres_lbfgs_gradient_tolerance)
      .rw("max_iterations", &O::max_iterations)
      .rw("max_inner_iterations", &O::max_inner_iterations)
      .rw("relative_preconditioned_gradient_tolerance",
          &O::relative_preconditioned_gradient_tolerance)
      .rw("relative_decrease_tolerance", &O::relative_decrease_tolerance)
      .rw("certification_target_relative_bound",
          &O::certification_target_relative_bound)
      .rw("certification_max_relative_bound",
          &O::certification_max_relative_bound)
      .rw("certification_goal_relative_bound",
          &O::certification_goal_relative_bound)
      .rw("proof_arithmetic", &O::proof_arithmetic)
      .rw("certification_max_rounding_gap", &O::certification_max_rounding_gap)
      .rw("min_relative_eta", &O::min_relative_eta)
      .rw("refine_rounded_solution", &O::refine_rounded_solution)
      .rw("test_certificate_after_escape", &O::test_certificate_after_escape)
      .rw("test_certificate_near_convergence",
          &O::test_certificate_near_convergence)
      .rw("newton_at_rank_d", &O::newton_at_rank_d)
      .rw("num_threads", &O::num_threads)
      .rw("max_time_s", &O::max_time_s)
      .rw("verbose", &O::verbose)
      .rw("callback", &O::callback,
          "callback(rank, iteration, F, gradient_norm, trust_radius) -> bool "
          "after every trust-region iteration; False stops the level.")
      .rw("progress", &O::progress,
          "progress(SolverProgress) at every stage boundary and iteration.");
  KeywordInit<O>(cls, "SolverOptions");
}

void BindSolverSummary(py::module_& m) {
  using S = SolverSummary;
  py::class_<S> cls(m, "SolverSummary",
                    "ceres_sesync::SolverSummary (sesync_solver.h); status is "
                    "the string of StatusString().");
  py::class_<S::Level> level(cls, "Level", "SolverSummary::Level");
  Fields(level)
      .ro("rank", &S::Level::rank)
      .ro("iterations", &S::Level::iterations)
      .ro("hessian_vector_products", &S::Level::hessian_vector_products)
      .ro("sdp_value", &S::Level::sdp_value)
      .ro("gradient_norm", &S::Level::gradient_norm)
      .ro("termination", &S::Level::termination)
      .ro("certified", &S::Level::certified)
      .ro("eta", &S::Level::eta)
      .ro("lambda_min_estimate", &S::Level::lambda_min_estimate)
      .ro("optimize_time_s", &S::Level::optimize_time_s)
      .ro("verify_time_s", &S::Level::verify_time_s)
      .ro("factorizations", &S::Level::factorizations)
      .ro("extended_factorizations", &S::Level::extended_factorizations)
      .ro("certificate_tests", &S::Level::certificate_tests)
      .ro("certificate_test_passed", &S::Level::certificate_test_passed);
  Fields(cls)
      .get("status", [](const S& s) { return s.StatusString(); })
      .ro("message", &S::message)
      .ro("dimension", &S::dimension)
      .ro("num_poses", &S::num_poses)
      .ro("num_measurements", &S::num_measurements)
      .ro("num_landmarks", &S::num_landmarks)
      .ro("num_landmark_measurements", &S::num_landmark_measurements)
      .ro("num_priors", &S::num_priors)
      .ro("objective", &S::objective)
      .ro("sdp_value", &S::sdp_value)
      .ro("lower_bound", &S::lower_bound)
      .ro("suboptimality_bound", &S::suboptimality_bound)
      .ro("relative_suboptimality_bound", &S::relative_suboptimality_bound)
      .ro("rounding_gap", &S::rounding_gap)
      .ro("lambda_min_estimate", &S::lambda_min_estimate)
      .ro("eta", &S::eta)
      .ro("proof_precision", &S::proof_precision)
      .ro("preconditioner", &S::preconditioner)
      .ro("relaxation_exact", &S::relaxation_exact)
      .ro("final_rank", &S::final_rank)
      .ro("iterations", &S::iterations)
      .ro("hessian_vector_products", &S::hessian_vector_products)
      .ro("factorizations", &S::factorizations)
      .ro("extended_factorizations", &S::extended_factorizations)
      .ro("certificate_tests", &S::certificate_tests)
      .ro("extended_proof_time_s", &S::extended_proof_time_s)
      .ro("levels", &S::levels)
      .ro("data_time_s", &S::data_time_s)
      .ro("initialization_time_s", &S::initialization_time_s)
      .ro("optimization_time_s", &S::optimization_time_s)
      .ro("verification_time_s", &S::verification_time_s)
      .ro("rounding_time_s", &S::rounding_time_s)
      .ro("total_time_s", &S::total_time_s)
      .get("certified", &S::certified);
  cls.def_property_readonly("brief_report", &S::BriefReport)
      .def_property_readonly("full_report", &S::FullReport);

  py::class_<SolveResult, S> result(
      m, "SolveResult",
      "solve()'s result: every SolverSummary field, the poses as numpy "
      "arrays, and summary (the full report).");
  Fields(result)
      .ro("rotations", &SolveResult::rotations,
          "(n, d, d) rotations, in the graph's pose order")
      .ro("translations", &SolveResult::translations,
          "(n, d) translations, in the graph's pose order")
      .ro("landmarks", &SolveResult::landmarks,
          "(L, d) landmark positions, in the graph's landmark order");
  result.def_property_readonly("summary", &S::FullReport);
}

void BindCertificate(py::module_& m) {
  using O = CertifyOptions;
  py::class_<O> options(m, "CertifyOptions",
                        "ceres_sesync::CertifyOptions (certification.h).");
  Fields(options)
      .rw("max_relative_suboptimality", &O::max_relative_suboptimality)
      .rw("target_relative_bound", &O::target_relative_bound)
      .rw("rotation_warning_tolerance", &O::rotation_warning_tolerance)
      .rw("improve_if_not_certified", &O::improve_if_not_certified)
      .rw("solver_options", &O::solver_options)
      .rw("goal_relative_suboptimality", &O::goal_relative_suboptimality)
      .rw("proof_arithmetic", &O::proof_arithmetic)
      .rw("num_threads", &O::num_threads);
  KeywordInit<O>(options, "CertifyOptions");

  using C = Certificate;
  py::class_<C> cls(m, "Certificate",
                    "ceres_sesync::Certificate (certification.h).");
  Fields(cls)
      .ro("certified", &C::certified)
      .ro("objective", &C::objective)
      .ro("rotation_objective", &C::rotation_objective)
      .ro("lambda_min", &C::lambda_min)
      .ro("eta", &C::eta)
      .ro("proof_precision", &C::proof_precision)
      .ro("factorizations", &C::factorizations)
      .ro("extended_factorizations", &C::extended_factorizations)
      .ro("extended_proof_time_s", &C::extended_proof_time_s)
      .ro("lower_bound", &C::lower_bound)
      .ro("suboptimality_bound", &C::suboptimality_bound)
      .ro("relative_suboptimality_bound", &C::relative_suboptimality_bound)
      .ro("max_rotation_error", &C::max_rotation_error)
      .get(
          "negative_curvature_direction",
          [](const C& c) -> py::object {
            const Eigen::VectorXd& v = c.negative_curvature_direction;
            if (v.size() == 0) return py::none();
            py::array_t<double> a(v.size());
            std::copy(v.data(), v.data() + v.size(), a.mutable_data());
            return std::move(a);
          },
          "unit v in R^{dn} with v^T S v < 0 (d-blocks in pose order), or "
          "None")
      .ro("negative_curvature", &C::negative_curvature)
      .ro("has_improved_poses", &C::has_improved_poses)
      .get(
          "improved_poses",
          [](const C& c) {
            return PosesTuple(c.improved_poses,
                              c.improvement_summary.dimension);
          },
          "(rotations, translations) of the improvement run, or None")
      .get(
          "improved_landmarks",
          [](const C& c) -> py::object {
            if (!c.has_improved_poses) return py::none();
            return LandmarksArray(c.improved_landmarks,
                                  c.improvement_summary.dimension);
          },
          "(L, d) landmark positions of the improvement run, or None")
      .ro("improvement_summary", &C::improvement_summary)
      .ro("time_s", &C::time_s);
  cls.def_property_readonly("brief_report", &C::BriefReport)
      .def_property_readonly("full_report", &C::FullReport)
      .def_property_readonly("summary", &C::FullReport);
}

void BindComponents(py::module_& m) {
  using S = ComponentsSummary;
  py::class_<S> cls(m, "ComponentsSummary",
                    "ceres_sesync::ComponentsSummary (component_solver.h).");
  py::class_<S::Component> component(cls, "Component",
                                     "ComponentsSummary::Component");
  Fields(component)
      .get(
          "poses", [](const S::Component& c) { return IndexArray(c.poses); },
          "indices of the component's poses in the whole graph")
      .get(
          "landmarks",
          [](const S::Component& c) { return IndexArray(c.landmarks); },
          "indices of the component's landmarks in the whole graph")
      .ro("num_measurements", &S::Component::num_measurements)
      .ro("num_landmark_measurements", &S::Component::num_landmark_measurements)
      .ro("num_priors", &S::Component::num_priors)
      .ro("gauge_vertex_id", &S::Component::gauge_vertex_id)
      .ro("summary", &S::Component::summary);
  Fields(cls)
      .get("status", [](const S& s) { return s.StatusString(); })
      .ro("message", &S::message)
      .ro("dimension", &S::dimension)
      .ro("num_poses", &S::num_poses)
      .ro("num_measurements", &S::num_measurements)
      .ro("num_landmarks", &S::num_landmarks)
      .ro("num_landmark_measurements", &S::num_landmark_measurements)
      .ro("num_priors", &S::num_priors)
      .ro("components", &S::components)
      .ro("objective", &S::objective)
      .ro("lower_bound", &S::lower_bound)
      .ro("suboptimality_bound", &S::suboptimality_bound)
      .ro("relative_suboptimality_bound", &S::relative_suboptimality_bound)
      .ro("total_time_s", &S::total_time_s)
      .get("certified", &S::certified);
  cls.def_property_readonly("brief_report", &S::BriefReport)
      .def_property_readonly("full_report", &S::FullReport);

  py::class_<ComponentsResult, S> result(
      m, "ComponentsResult",
      "solve_components()'s result: every ComponentsSummary field, the poses "
      "and landmark positions of the whole graph as numpy arrays, and summary "
      "(the full report).");
  Fields(result)
      .ro("rotations", &ComponentsResult::rotations)
      .ro("translations", &ComponentsResult::translations)
      .ro("landmarks", &ComponentsResult::landmarks);
  result.def_property_readonly("summary", &S::FullReport);
}

void BindPoseGraph(py::module_& m) {
  py::class_<Measurements> ms(
      m, "Measurements",
      "The measurements of a PoseGraph as arrays: measurement k is the pose "
      "of j[k] relative to i[k]: R[k] ~ R_i^T R_j, t[k] ~ R_i^T (t_j - t_i), "
      "with precisions kappa[k] (rotation) and tau[k] (translation).");
  Fields(ms)
      .ro("i", &Measurements::i)
      .ro("j", &Measurements::j)
      .ro("R", &Measurements::R)
      .ro("t", &Measurements::t)
      .ro("kappa", &Measurements::kappa)
      .ro("tau", &Measurements::tau);
  ms.def("__len__", [](const Measurements& s) { return s.size; });

  py::class_<PoseGraph> cls(
      m, "PoseGraph",
      "A pose graph (pose_graph.h); immutable. Made by read_g2o(), "
      "PoseGraph.from_measurements() or generate_cube().");
  Fields(cls)
      .ro("dimension", &PoseGraph::dimension)
      .ro("num_poses", &PoseGraph::num_poses)
      .get(
          "measurements",
          [](const PoseGraph& g) {
            const int d = g.dimension;
            const py::ssize_t n =
                static_cast<py::ssize_t>(g.measurements.size());
            py::array_t<int64_t> i(n), j(n);
            DoubleArray R(
                {n, static_cast<py::ssize_t>(d), static_cast<py::ssize_t>(d)});
            DoubleArray t({n, static_cast<py::ssize_t>(d)});
            py::array_t<double> kappa(n), tau(n);
            auto r = R.mutable_unchecked<3>();
            auto s = t.mutable_unchecked<2>();
            for (py::ssize_t k = 0; k < n; ++k) {
              const RelativePoseMeasurement& e = g.measurements[k];
              i.mutable_at(k) = e.i;
              j.mutable_at(k) = e.j;
              for (int a = 0; a < d; ++a) {
                for (int b = 0; b < d; ++b) r(k, a, b) = e.R(a, b);
                s(k, a) = e.t(a);
              }
              kappa.mutable_at(k) = e.kappa;
              tau.mutable_at(k) = e.tau;
            }
            Measurements out{i, j, R, t, kappa, tau, n};
            return out;
          },
          "the measurements as arrays (a copy)")
      .get(
          "vertex_ids",
          [](const PoseGraph& g) { return IndexArray(g.vertex_ids); },
          "original vertex id of each pose")
      .get(
          "index_of_vertex_id",
          [](const PoseGraph& g) {
            py::dict d;
            for (const auto& [id, index] : g.index_of_vertex_id) {
              d[py::int_(id)] = index;
            }
            return d;
          },
          "{vertex id: pose index}")
      .get(
          "initial_poses",
          [](const PoseGraph& g) {
            return PosesTuple(g.initial_poses, g.dimension);
          },
          "(rotations, translations) from the VERTEX lines, or None")
      .get(
          "fixed_pose",
          [](const PoseGraph& g) -> py::object {
            if (g.fixed_pose < 0) return py::none();
            return py::int_(g.fixed_pose);
          },
          "index of the FIX pose, or None")
      .ro("num_landmarks", &PoseGraph::num_landmarks)
      .get(
          "landmark_measurements",
          [](const PoseGraph& g) {
            const int d = g.dimension;
            const py::ssize_t n =
                static_cast<py::ssize_t>(g.landmark_measurements.size());
            py::array_t<int64_t> i(n), l(n);
            DoubleArray z({n, static_cast<py::ssize_t>(d)});
            py::array_t<double> nu(n);
            auto zz = z.mutable_unchecked<2>();
            for (py::ssize_t k = 0; k < n; ++k) {
              const LandmarkMeasurement& o = g.landmark_measurements[k];
              i.mutable_at(k) = o.i;
              l.mutable_at(k) = o.l;
              for (int a = 0; a < d; ++a) zz(k, a) = o.z(a);
              nu.mutable_at(k) = o.nu;
            }
            py::dict out;
            out["i"] = i;
            out["l"] = l;
            out["z"] = z;
            out["nu"] = nu;
            return out;
          },
          "pose-to-landmark measurements as arrays {i, l, z (m, d), nu}")
      .get(
          "landmark_ids",
          [](const PoseGraph& g) { return IndexArray(g.landmark_ids); },
          "original vertex id of each landmark")
      .get(
          "index_of_landmark_id",
          [](const PoseGraph& g) {
            py::dict d;
            for (const auto& [id, index] : g.index_of_landmark_id) {
              d[py::int_(id)] = index;
            }
            return d;
          },
          "{landmark id: landmark index}")
      .get(
          "initial_landmarks",
          [](const PoseGraph& g) -> py::object {
            if (g.initial_landmarks.empty()) return py::none();
            const int d = g.dimension;
            DoubleArray p({static_cast<py::ssize_t>(g.num_landmarks),
                           static_cast<py::ssize_t>(d)});
            auto pp = p.mutable_unchecked<2>();
            for (int k = 0; k < g.num_landmarks; ++k) {
              for (int a = 0; a < d; ++a) pp(k, a) = g.initial_landmarks[k](a);
            }
            return p;
          },
          "(L, d) landmark positions from the VERTEX lines, or None")
      .get(
          "priors",
          [](const PoseGraph& g) {
            const int d = g.dimension;
            const py::ssize_t n = static_cast<py::ssize_t>(g.priors.size());
            py::array_t<int64_t> i(n);
            DoubleArray R(
                {n, static_cast<py::ssize_t>(d), static_cast<py::ssize_t>(d)});
            DoubleArray t({n, static_cast<py::ssize_t>(d)});
            py::array_t<double> kappa(n), tau(n);
            auto r = R.mutable_unchecked<3>();
            auto s = t.mutable_unchecked<2>();
            const double nan = std::numeric_limits<double>::quiet_NaN();
            for (py::ssize_t k = 0; k < n; ++k) {
              const PosePrior& p = g.priors[k];
              i.mutable_at(k) = p.i;
              for (int a = 0; a < d; ++a) {
                for (int b = 0; b < d; ++b) {
                  r(k, a, b) = p.has_rotation() ? p.R(a, b) : nan;
                }
                s(k, a) = p.has_position() ? p.t(a) : nan;
              }
              kappa.mutable_at(k) = p.kappa;
              tau.mutable_at(k) = p.tau;
            }
            py::dict out;
            out["i"] = i;
            out["R"] = R;
            out["t"] = t;
            out["kappa"] = kappa;
            out["tau"] = tau;
            return out;
          },
          "pose priors as arrays {i, R (k, d, d), t (k, d), kappa, tau}; the "
          "unused part of a position- or rotation-only prior is NaN");
  cls.def_property_readonly("num_measurements", [](const PoseGraph& g) {
    return g.measurements.size();
  });
  cls.def(
      "connected_components",
      [](const PoseGraph& g) {
        std::vector<int> label;
        ConnectedComponents(g, &label);
        return IndexArray(label);
      },
      "Component label (0, 1, ...; in order of first pose) of every pose.");

  py::class_<PoseGraphComponent> part(
      m, "PoseGraphComponent",
      "ceres_sesync::PoseGraphComponent (component_solver.h): one connected "
      "component of a graph, as a graph of its own.");
  Fields(part)
      .get(
          "poses",
          [](const PoseGraphComponent& c) { return IndexArray(c.poses); },
          "indices of the component's poses in the whole graph")
      .get(
          "measurements",
          [](const PoseGraphComponent& c) {
            return IndexArray(c.measurements);
          },
          "indices of the component's measurements in the whole graph")
      .get(
          "landmarks",
          [](const PoseGraphComponent& c) { return IndexArray(c.landmarks); },
          "indices of the component's landmarks in the whole graph")
      .get(
          "landmark_measurements",
          [](const PoseGraphComponent& c) {
            return IndexArray(c.landmark_measurements);
          },
          "indices of the component's landmark measurements in the whole "
          "graph")
      .get(
          "priors",
          [](const PoseGraphComponent& c) { return IndexArray(c.priors); },
          "indices of the component's priors in the whole graph")
      .ro("graph", &PoseGraphComponent::graph);
  cls.def("split_into_components", &SplitIntoComponents,
          "The connected components (PoseGraphComponent), in order of their "
          "first pose.");

  m.def(
      "_pose_graph_from_measurements",
      [](int d, py::handle i, py::handle j, py::handle R, py::handle t,
         py::handle kappa, py::handle tau, py::object num_poses,
         py::object vertex_ids, py::object initial_rotations,
         py::object initial_translations, py::object fixed_pose,
         bool allow_disconnected) {
        if (d != 2 && d != 3) {
          throw py::value_error("dimension must be 2 or 3, not " +
                                std::to_string(d));
        }
        const auto I = ToIndexArray(i, "i", -1);
        const py::ssize_t m = I.shape(0);
        const auto J = ToIndexArray(j, "j", m);
        const DoubleArray Rs = ToDoubleArray(R, "R", {m, d, d});
        const DoubleArray ts = ToDoubleArray(t, "t", {m, d});
        const DoubleArray kappas = ToDoubleArray(kappa, "kappa", {m});
        const DoubleArray taus = ToDoubleArray(tau, "tau", {m});
        int64_t n = 0;
        for (py::ssize_t k = 0; k < m; ++k) {
          n = std::max({n, I.at(k) + 1, J.at(k) + 1});
        }
        if (!num_poses.is_none()) {
          const int64_t given = num_poses.cast<int64_t>();
          if (given < n) {
            throw py::value_error("num_poses is " + std::to_string(given) +
                                  ", but the measurements refer to pose " +
                                  std::to_string(n - 1));
          }
          n = given;
        }
        if (n < 1) throw py::value_error("a pose graph needs a pose");
        if (n > std::numeric_limits<int>::max()) {
          throw py::value_error("too many poses");
        }
        PoseGraph g;
        g.dimension = d;
        if (vertex_ids.is_none()) {
          for (int64_t v = 0; v < n; ++v) g.AddVertex(v);
        } else {
          const auto ids = ToIndexArray(vertex_ids, "vertex_ids", n);
          for (int64_t v = 0; v < n; ++v) {
            if (g.AddVertex(ids.at(v)) != v) {
              throw py::value_error("vertex_ids: duplicate id " +
                                    std::to_string(ids.at(v)));
            }
          }
        }
        auto r = Rs.unchecked<3>();
        auto s = ts.unchecked<2>();
        for (py::ssize_t k = 0; k < m; ++k) {
          RelativePoseMeasurement e;
          e.i = static_cast<int>(std::max<int64_t>(
              -1, std::min<int64_t>(I.at(k), std::numeric_limits<int>::max())));
          e.j = static_cast<int>(std::max<int64_t>(
              -1, std::min<int64_t>(J.at(k), std::numeric_limits<int>::max())));
          e.R.resize(d, d);
          e.t.resize(d);
          for (int a = 0; a < d; ++a) {
            for (int b = 0; b < d; ++b) e.R(a, b) = r(k, a, b);
            e.t(a) = s(k, a);
          }
          e.kappa = kappas.at(k);
          e.tau = taus.at(k);
          g.measurements.push_back(std::move(e));
        }
        if (initial_rotations.is_none() != initial_translations.is_none()) {
          throw py::value_error(
              "initial_rotations and initial_translations go together");
        }
        if (!initial_rotations.is_none()) {
          g.initial_poses = ToPoses(g, initial_rotations, initial_translations);
        }
        if (!fixed_pose.is_none()) g.fixed_pose = fixed_pose.cast<int>();
        std::string error;
        ValidationOptions validation;
        validation.require_connected = !allow_disconnected;
        if (!ValidatePoseGraph(g, validation, &error)) {
          if (error.find("disconnected") != std::string::npos) {
            error +=
                " (allow_disconnected=True accepts it; solve_components() "
                "solves each component)";
          }
          throw py::value_error(error);
        }
        return g;
      });
}

// Raises ValueError (bad contents) with the library's message.
[[noreturn]] void InputError(const std::string& message) {
  throw py::value_error(message);
}

// The writers' failures are about the file system.
void WriteOrRaise(bool ok, const std::string& error) {
  if (!ok) {
    PyErr_SetString(PyExc_OSError, error.c_str());
    throw py::error_already_set();
  }
}

void BindIo(py::module_& m) {
  using O = G2oReadOptions;
  py::class_<O> options(m, "G2oReadOptions",
                        "ceres_sesync::G2oReadOptions (g2o_io.h).");
  Fields(options)
      .rw("skip_unsupported_tags", &O::skip_unsupported_tags)
      .rw("allow_disconnected", &O::allow_disconnected);
  KeywordInit<O>(options, "G2oReadOptions");

  using S = G2oReadSummary;
  py::class_<S> summary(m, "G2oReadSummary",
                        "ceres_sesync::G2oReadSummary (g2o_io.h).");
  Fields(summary)
      .ro("num_vertices", &S::num_vertices)
      .ro("num_edges", &S::num_edges)
      .ro("num_landmarks", &S::num_landmarks)
      .ro("num_landmark_edges", &S::num_landmark_edges)
      .ro("num_priors", &S::num_priors)
      .ro("num_offset_parameters", &S::num_offset_parameters)
      .ro("num_skipped_lines", &S::num_skipped_lines)
      .ro("skipped_tags", &S::skipped_tags)
      .ro("num_normalized_quaternions", &S::num_normalized_quaternions)
      .ro("num_indefinite_information", &S::num_indefinite_information)
      .ro("has_fix", &S::has_fix);

  m.def("_read_g2o", [](const std::string& path, const O& options) {
    PoseGraph graph;
    S summary;
    std::string error;
    bool ok;
    {
      py::gil_scoped_release release;
      ok = ReadG2oFile(path, options, &graph, &error, &summary);
    }
    if (!ok) InputError(error);
    return py::make_tuple(std::move(graph), std::move(summary));
  });
  m.def("_read_g2o_poses", [](const std::string& path, const PoseGraph& graph) {
    Poses poses;
    std::string error;
    if (!ReadG2oPoses(path, graph, &poses, &error)) InputError(error);
    return PosesTuple(poses, graph.dimension);
  });
  m.def("_read_g2o_solution",
        [](const std::string& path, const PoseGraph& graph) {
          Solution solution;
          std::string error;
          if (!ReadG2oSolution(path, graph, &solution, &error))
            InputError(error);
          const int d = graph.dimension;
          return py::make_tuple(RotationsArray(solution.poses, d),
                                TranslationsArray(solution.poses, d),
                                LandmarksArray(solution.landmarks, d));
        });
  m.def("_write_g2o", [](const std::string& path, const PoseGraph& graph,
                         py::handle rotations, py::handle translations,
                         py::handle landmarks) {
    Poses poses;
    if (!rotations.is_none() || !translations.is_none()) {
      poses = ToPoses(graph, rotations, translations, true);
    }
    LandmarkPositions positions;
    if (!landmarks.is_none()) positions = ToLandmarks(graph, landmarks, true);
    std::string error;
    WriteOrRaise(WriteG2oFile(path, graph, poses, positions, &error), error);
  });
  m.def("_write_g2o_poses", [](const std::string& path, const PoseGraph& graph,
                               py::handle rotations, py::handle translations,
                               py::handle landmarks) {
    Solution solution{ToPoses(graph, rotations, translations, true), {}};
    if (!landmarks.is_none()) {
      solution.landmarks = ToLandmarks(graph, landmarks, true);
    }
    std::string error;
    WriteOrRaise(landmarks.is_none()
                     ? WriteG2oPoses(path, graph, solution.poses, &error)
                     : WriteG2oSolution(path, graph, solution, &error),
                 error);
  });
  m.def("_write_tum", [](const std::string& path, const PoseGraph& graph,
                         py::handle rotations, py::handle translations) {
    const Poses poses = ToPoses(graph, rotations, translations, true);
    std::string error;
    WriteOrRaise(WriteTumFile(path, graph, poses, &error), error);
  });
  m.def(
      "_evaluate_objective", [](const PoseGraph& graph, py::handle rotations,
                                py::handle translations, py::handle landmarks) {
        return EvaluateObjective(graph, ToPoses(graph, rotations, translations),
                                 ToLandmarks(graph, landmarks));
      });
}

void BindCube(py::module_& m) {
  using O = CubeOptions;
  py::class_<O> cls(m, "CubeOptions",
                    "ceres_sesync::CubeOptions (cube_generator.h).");
  Fields(cls)
      .rw("dimension", &O::dimension)
      .rw("side", &O::side)
      .rw("loop_closure_probability", &O::loop_closure_probability)
      .rw("loop_closure_radius", &O::loop_closure_radius)
      .rw("kappa", &O::kappa)
      .rw("tau", &O::tau)
      .rw("spacing", &O::spacing)
      .rw("seed", &O::seed);
  KeywordInit<O>(cls, "CubeOptions");
  m.def("_generate_cube", [](const O& options) {
    PoseGraph graph;
    Poses truth;
    std::string error;
    if (!GenerateCube(options, &graph, &truth, &error)) InputError(error);
    const int d = graph.dimension;
    return py::make_tuple(std::move(graph), RotationsArray(truth, d),
                          TranslationsArray(truth, d));
  });
  m.def(
      "_expected_ground_truth_objective",
      static_cast<double (*)(int, int, double)>(&ExpectedGroundTruthObjective));

  using CO = CityOptions;
  py::class_<CO> city(m, "CityOptions",
                      "ceres_sesync::CityOptions (city_generator.h).");
  Fields(city)
      .rw("dimension", &CO::dimension)
      .rw("num_poses", &CO::num_poses)
      .rw("lattice_scale", &CO::lattice_scale)
      .rw("levels", &CO::levels)
      .rw("turn_probability", &CO::turn_probability)
      .rw("loop_closure_probability", &CO::loop_closure_probability)
      .rw("max_loop_closures_per_visit", &CO::max_loop_closures_per_visit)
      .rw("kappa", &CO::kappa)
      .rw("tau", &CO::tau)
      .rw("spacing", &CO::spacing)
      .rw("seed", &CO::seed);
  KeywordInit<CO>(city, "CityOptions");
  m.def("_generate_city", [](const CO& options) {
    PoseGraph graph;
    Poses truth;
    std::string error;
    bool ok;
    {
      py::gil_scoped_release release;  // 10^6 poses take seconds
      ok = GenerateCity(options, &graph, &truth, &error);
    }
    if (!ok) InputError(error);
    const int d = graph.dimension;
    return py::make_tuple(std::move(graph), RotationsArray(truth, d),
                          TranslationsArray(truth, d));
  });
}

void BindLandmarkGenerator(py::module_& m) {
  using O = LandmarkGraphOptions;
  py::class_<O> cls(
      m, "LandmarkGraphOptions",
      "ceres_sesync::LandmarkGraphOptions (landmark_generator.h).");
  Fields(cls)
      .rw("dimension", &O::dimension)
      .rw("num_poses", &O::num_poses)
      .rw("step_length", &O::step_length)
      .rw("block_length", &O::block_length)
      .rw("turn_probability", &O::turn_probability)
      .rw("world_size", &O::world_size)
      .rw("num_landmarks", &O::num_landmarks)
      .rw("sensor_range", &O::sensor_range)
      .rw("detection_probability", &O::detection_probability)
      .rw("max_observations_per_pose", &O::max_observations_per_pose)
      .rw("kappa", &O::kappa)
      .rw("tau", &O::tau)
      .rw("landmark_nu", &O::landmark_nu)
      .rw("gps_interval", &O::gps_interval)
      .rw("gps_tau", &O::gps_tau)
      .rw("start_prior", &O::start_prior)
      .rw("start_prior_kappa", &O::start_prior_kappa)
      .rw("start_prior_tau", &O::start_prior_tau)
      .rw("noiseless", &O::noiseless)
      .rw("seed", &O::seed);
  KeywordInit<O>(cls, "LandmarkGraphOptions");
  m.def("_victoria_park_like_options",
        [] { return VictoriaParkLikeOptions(); });
  m.def(
      "_expected_landmark_graph_objective",
      static_cast<double (*)(const PoseGraph&)>(&ExpectedGroundTruthObjective));
  m.def("_generate_landmarks", [](const O& options) {
    PoseGraph graph;
    Solution truth;
    std::string error;
    bool ok;
    {
      py::gil_scoped_release release;
      ok = GenerateLandmarkGraph(options, &graph, &truth, &error);
    }
    if (!ok) InputError(error);
    const int d = graph.dimension;
    return py::make_tuple(std::move(graph), RotationsArray(truth.poses, d),
                          TranslationsArray(truth.poses, d),
                          LandmarksArray(truth.landmarks, d));
  });
}

void BindSolvers(py::module_& m) {
  m.def("_solve", [](const PoseGraph& graph, SolverOptions options,
                     py::object initial_rotations) {
    Poses initial;
    const bool has_initial = !initial_rotations.is_none();
    if (has_initial) {  // Solve() uses the rotations only.
      const py::ssize_t n = graph.num_poses, d = graph.dimension;
      DoubleArray zeros(std::vector<py::ssize_t>{n, d});
      std::fill(zeros.mutable_data(), zeros.mutable_data() + n * d, 0.0);
      initial = ToPoses(graph, initial_rotations, zeros);
    }
    MakeInterruptible(&options);
    SolveResult result;
    Solution solution;
    {
      py::gil_scoped_release release;
      if (has_initial) {
        Solve(graph, initial, options, &solution, &result);
      } else {
        Solve(graph, options, &solution, &result);
      }
    }
    if (result.status == Status::kInvalidInput) InputError(result.message);
    result.rotations = RotationsArray(solution.poses, graph.dimension);
    result.translations = TranslationsArray(solution.poses, graph.dimension);
    result.landmarks = LandmarksArray(solution.landmarks, graph.dimension);
    return result;
  });
  m.def("_solve_by_component", [](const PoseGraph& graph,
                                  SolverOptions options) {
    MakeInterruptible(&options);
    ComponentsResult result;
    Solution solution;
    {
      py::gil_scoped_release release;
      SolveByComponent(graph, options, &solution, &result);
    }
    if (result.status == Status::kInvalidInput) InputError(result.message);
    result.rotations = RotationsArray(solution.poses, graph.dimension);
    result.translations = TranslationsArray(solution.poses, graph.dimension);
    result.landmarks = LandmarksArray(solution.landmarks, graph.dimension);
    return result;
  });
  m.def("_certify", [](const PoseGraph& graph, py::handle rotations,
                       py::handle translations, py::handle landmarks,
                       CertifyOptions options) {
    const Solution candidate{ToPoses(graph, rotations, translations),
                             ToLandmarks(graph, landmarks)};
    MakeInterruptible(&options.solver_options);
    Certificate certificate;
    std::string error;
    bool ok;
    {
      py::gil_scoped_release release;
      ok = Certify(graph, candidate, options, &certificate, &error);
    }
    if (!ok) InputError(error);
    return certificate;
  });
  m.def("_apply_keywords",
        [](py::handle target, const py::dict& kwargs,
           const std::string& where) { ApplyKeywords(target, kwargs, where); });
}

void InitLogging() {
  // Warnings of the library (e.g. Certify projecting rotations) go to
  // stderr; INFO lines appear only with SolverOptions::verbose.
  if (!google::IsGoogleLoggingInitialized()) {
    google::InitGoogleLogging("ceres_sesync");
  }
  FLAGS_logtostderr = true;
}

// ---- the robust solve (robust_solver.h) ------------------------------------

void BindRobust(py::module_& m) {
  using O = RobustSolverOptions;
  py::class_<O> options(m, "RobustSolverOptions",
                        "ceres_sesync::RobustSolverOptions (robust_solver.h).");
  py::enum_<O::KnownInliers> known(options, "KnownInliers",
                                   "RobustSolverOptions::KnownInliers");
  known.value("none", O::KnownInliers::kNone)
      .value("odometry", O::KnownInliers::kOdometry);
  AcceptNames(known);
  Fields(options)
      .rw("solver_options", &O::solver_options)
      .rw("inlier_threshold", &O::inlier_threshold)
      .rw("inlier_probability", &O::inlier_probability)
      .rw("gnc_threshold_fractions", &O::gnc_threshold_fractions)
      .rw("initial_max_rank", &O::initial_max_rank)
      .rw("gnc_max_rank", &O::gnc_max_rank)
      .rw("gnc_relative_gradient_tolerance",
          &O::gnc_relative_gradient_tolerance)
      .rw("gnc_relative_decrease_tolerance",
          &O::gnc_relative_decrease_tolerance)
      .rw("gnc_refine_rounded_solution", &O::gnc_refine_rounded_solution)
      .rw("mu_step", &O::mu_step)
      .rw("max_iterations", &O::max_iterations)
      .rw("max_time_s", &O::max_time_s)
      .rw("weight_tolerance", &O::weight_tolerance)
      .rw("relative_cost_tolerance", &O::relative_cost_tolerance)
      .rw("max_consistency_rounds", &O::max_consistency_rounds)
      .rw("max_readmission_trials", &O::max_readmission_trials)
      .rw("readmission_max_cost", &O::readmission_max_cost)
      .rw("readmission_min_scale", &O::readmission_min_scale)
      .rw("max_removal_trials", &O::max_removal_trials)
      .rw("known_inliers", &O::known_inliers);
  KeywordInit<O>(options, "RobustSolverOptions");

  using S = RobustSolverSummary;
  auto solver_status = [](SolverSummary::Status status) {
    SolverSummary s;
    s.status = status;
    return s.StatusString();
  };
  auto robust_status = [](S::Status status) {
    S s;
    s.status = status;
    return s.StatusString();
  };
  py::class_<S> cls(m, "RobustSolverSummary",
                    "ceres_sesync::RobustSolverSummary (robust_solver.h); "
                    "status is the string of StatusString().");
  py::class_<S::Edge> edge(cls, "Edge", "RobustSolverSummary::Edge");
  Fields(edge)
      .get("kind", [](const S::Edge& e) { return e.KindString(); })
      .ro("index", &S::Edge::index)
      .ro("vertex_i", &S::Edge::vertex_i)
      .ro("vertex_j", &S::Edge::vertex_j)
      .ro("weight", &S::Edge::weight)
      .ro("inlier", &S::Edge::inlier)
      .ro("known_inlier", &S::Edge::known_inlier)
      .ro("rotation_residual_deg", &S::Edge::rotation_residual_deg)
      .ro("translation_residual", &S::Edge::translation_residual)
      .ro("cost", &S::Edge::cost)
      .ro("threshold", &S::Edge::threshold);
  py::class_<S::Iteration> iteration(cls, "Iteration",
                                     "RobustSolverSummary::Iteration");
  Fields(iteration)
      .ro("mu", &S::Iteration::mu)
      .ro("surrogate_cost", &S::Iteration::surrogate_cost)
      .ro("num_zero_weights", &S::Iteration::num_zero_weights)
      .ro("num_unit_weights", &S::Iteration::num_unit_weights)
      .get("status",
           [solver_status](const S::Iteration& it) {
             return solver_status(it.status);
           })
      .ro("rank", &S::Iteration::rank)
      .ro("solver_iterations", &S::Iteration::solver_iterations)
      .ro("optimization_time_s", &S::Iteration::optimization_time_s)
      .ro("verification_time_s", &S::Iteration::verification_time_s)
      .ro("time_s", &S::Iteration::time_s);
  py::class_<S::Run> run(cls, "Run", "RobustSolverSummary::Run");
  Fields(run)
      .ro("gnc_threshold", &S::Run::gnc_threshold)
      .get("status",
           [robust_status](const S::Run& r) { return robust_status(r.status); })
      .ro("iterations", &S::Run::iterations)
      .ro("consistency_rounds", &S::Run::consistency_rounds)
      .ro("readmission_trials", &S::Run::readmission_trials)
      .ro("readmissions", &S::Run::readmissions)
      .ro("removal_trials", &S::Run::removal_trials)
      .ro("removals", &S::Run::removals)
      .ro("num_outliers", &S::Run::num_outliers)
      .ro("tls_cost", &S::Run::tls_cost)
      .ro("certified", &S::Run::certified)
      .ro("time_s", &S::Run::time_s);
  Fields(cls)
      .get("status", [](const S& s) { return s.StatusString(); })
      .ro("message", &S::message)
      .ro("dimension", &S::dimension)
      .ro("num_poses", &S::num_poses)
      .ro("num_measurements", &S::num_measurements)
      .ro("num_landmark_measurements", &S::num_landmark_measurements)
      .ro("num_priors", &S::num_priors)
      .ro("inlier_threshold", &S::inlier_threshold)
      .ro("gnc_threshold", &S::gnc_threshold)
      .ro("runs", &S::runs)
      .ro("selected_run", &S::selected_run)
      .ro("initial_mu", &S::initial_mu)
      .ro("iterations", &S::iterations)
      .ro("history", &S::history)
      .ro("weights_binary", &S::weights_binary)
      .ro("edges", &S::edges)
      .ro("num_inliers", &S::num_inliers)
      .ro("num_outliers", &S::num_outliers)
      .get("outlier_edges",
           [](const S& s) { return IndexArray(s.outlier_edges); })
      .get("outlier_landmark_measurements",
           [](const S& s) {
             return IndexArray(s.outlier_landmark_measurements);
           })
      .get("outlier_priors",
           [](const S& s) { return IndexArray(s.outlier_priors); })
      .ro("num_rejected_within_threshold", &S::num_rejected_within_threshold)
      .ro("num_accepted_beyond_threshold", &S::num_accepted_beyond_threshold)
      .ro("initial_summary", &S::initial_summary)
      .ro("inlier_summary", &S::inlier_summary)
      .ro("consistency_rounds", &S::consistency_rounds)
      .ro("readmissions", &S::readmissions)
      .ro("removals", &S::removals)
      .ro("pattern_rebuilds", &S::pattern_rebuilds)
      .ro("concurrent_runs", &S::concurrent_runs)
      .ro("initial_time_s", &S::initial_time_s)
      .ro("gnc_time_s", &S::gnc_time_s)
      .ro("inlier_time_s", &S::inlier_time_s)
      .ro("total_time_s", &S::total_time_s)
      .get("certified", &S::certified);
  cls.def_property_readonly("brief_report", &S::BriefReport)
      .def("full_report", &S::FullReport, py::arg("all_edges") = false);

  py::class_<RobustResult, S> result(
      m, "RobustResult",
      "solve(robust=True)'s result: every RobustSolverSummary field, the "
      "poses as numpy arrays, the weights and inlier flags as arrays, the "
      "inlier problem's objective and bounds, and summary (the full "
      "report).");
  Fields(result)
      .ro("rotations", &RobustResult::rotations,
          "(n, d, d) rotations of the inlier problem's solution")
      .ro("translations", &RobustResult::translations,
          "(n, d) translations of the inlier problem's solution")
      .ro("landmarks", &RobustResult::landmarks,
          "(L, d) landmark positions of the inlier problem's solution");
  // The inlier problem's numbers under the names solve() returns them
  // (certified and status stay RobustSolverSummary's: the inlier problem's
  // certificate, and GNC's outcome).
  result
      .def_property_readonly(
          "objective",
          [](const RobustResult& r) { return r.inlier_summary.objective; })
      .def_property_readonly(
          "lower_bound",
          [](const RobustResult& r) { return r.inlier_summary.lower_bound; })
      .def_property_readonly("suboptimality_bound",
                             [](const RobustResult& r) {
                               return r.inlier_summary.suboptimality_bound;
                             })
      .def_property_readonly(
          "relative_suboptimality_bound",
          [](const RobustResult& r) {
            return r.inlier_summary.relative_suboptimality_bound;
          })
      .def_property_readonly("relaxation_exact", [](const RobustResult& r) {
        return r.inlier_summary.relaxation_exact;
      });
  result.def_property_readonly("weights", [](const RobustResult& r) {
    DoubleArray w(static_cast<py::ssize_t>(r.edges.size()));
    for (size_t k = 0; k < r.edges.size(); ++k) {
      w.mutable_data()[k] = r.edges[k].weight;
    }
    return w;
  });
  result.def_property_readonly("inliers", [](const RobustResult& r) {
    py::array_t<bool> a(static_cast<py::ssize_t>(r.edges.size()));
    for (size_t k = 0; k < r.edges.size(); ++k) {
      a.mutable_data()[k] = r.edges[k].inlier;
    }
    return a;
  });
  result.def_property_readonly(
      "summary", [](const RobustResult& r) { return r.FullReport(); });

  m.def("_solve_robust",
        [](const PoseGraph& graph, RobustSolverOptions options) {
          MakeInterruptible(&options.solver_options);
          RobustResult result;
          Solution solution;
          {
            py::gil_scoped_release release;
            SolveRobust(graph, options, &solution, &result);
          }
          if (result.status == RobustSolverSummary::Status::kInvalidInput) {
            InputError(result.message);
          }
          const int d = graph.dimension;
          result.rotations = RotationsArray(solution.poses, d);
          result.translations = TranslationsArray(solution.poses, d);
          result.landmarks = LandmarksArray(solution.landmarks, d);
          return result;
        });
}

}  // namespace

}  // namespace ceres_sesync::python

PYBIND11_MODULE(_ceres_sesync, m) {
  using namespace ceres_sesync::python;
  m.doc() =
      "C++ core of the ceres_sesync package (SE-Sync certifiably correct "
      "pose-graph optimization); use the package, not this module.";
  m.attr("__version__") = CERES_SESYNC_VERSION;
  InitLogging();
  BindEnums(m);
  BindSolverProgress(m);
  BindSolverOptions(m);
  BindSolverSummary(m);
  BindCertificate(m);
  BindComponents(m);
  BindPoseGraph(m);
  BindIo(m);
  BindCube(m);
  BindLandmarkGenerator(m);
  BindSolvers(m);
  BindRobust(m);
  // Process-wide, so the module never calls it itself (process_memory.h).
  m.def("keep_freed_memory", &ceres_sesync::KeepFreedMemory,
        "Process-wide: keep freed memory in the process for the next solve "
        "(ceres_sesync::KeepFreedMemory, process_memory.h). Call once, "
        "before solving many graphs; returns False where it is not "
        "available (not glibc).");
}
