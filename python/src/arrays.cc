#include "python/src/arrays.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace ceres_sesync::python {
namespace {

std::string ShapeString(const std::vector<py::ssize_t>& shape) {
  std::ostringstream s;
  s << "(";
  for (size_t k = 0; k < shape.size(); ++k) {
    if (k) s << ", ";
    if (shape[k] < 0) {
      s << "m";
    } else {
      s << shape[k];
    }
  }
  s << (shape.size() == 1 ? ",)" : ")");
  return s.str();
}

template <typename Array>
void CheckShape(const Array& a, const std::string& name,
                const std::vector<py::ssize_t>& shape) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  std::vector<py::ssize_t> actual(a.shape(), a.shape() + a.ndim());
  for (size_t k = 0; ok && k < shape.size(); ++k) {
    ok = shape[k] < 0 || actual[k] == shape[k];
  }
  if (!ok) {
    throw py::value_error(name + " must have shape " + ShapeString(shape) +
                          ", not " + ShapeString(actual));
  }
}

}  // namespace

DoubleArray ToDoubleArray(py::handle value, const std::string& name,
                          const std::vector<py::ssize_t>& shape) {
  if (value.is_none())
    throw py::type_error(name + " must be an array, not None");
  py::array input = py::array::ensure(value);
  if (!input) {
    PyErr_Clear();
    throw py::type_error(name + " must be an array of numbers");
  }
  const char kind = input.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::type_error(name +
                         " must be an array of real numbers, not dtype " +
                         std::string(py::str(input.dtype())));
  }
  DoubleArray a = DoubleArray::ensure(input);
  if (!a) throw py::error_already_set();
  CheckShape(a, name, shape);
  return a;
}

py::array_t<int64_t, py::array::c_style> ToIndexArray(py::handle value,
                                                      const std::string& name,
                                                      py::ssize_t m) {
  py::array input = py::array::ensure(value);
  if (!input) {
    PyErr_Clear();
    throw py::type_error(name + " must be an array of integers");
  }
  const char kind = input.dtype().kind();
  // An empty list becomes a float array; accept it as "no indices".
  if (kind != 'i' && kind != 'u' && !(input.size() == 0 && kind == 'f')) {
    throw py::type_error(name + " must hold integers, not dtype " +
                         std::string(py::str(input.dtype())));
  }
  auto a =
      py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(
          input);
  if (!a) throw py::error_already_set();
  CheckShape(a, name, {m});
  return a;
}

Poses ToPoses(const PoseGraph& graph, py::handle rotations,
              py::handle translations, bool require_finite) {
  const int d = graph.dimension;
  const py::ssize_t n = graph.num_poses;
  const DoubleArray R = ToDoubleArray(rotations, "rotations", {n, d, d});
  const DoubleArray t = ToDoubleArray(translations, "translations", {n, d});
  if (require_finite) {
    for (const auto& [a, name] :
         {std::pair{&R, "rotations"}, std::pair{&t, "translations"}}) {
      const double* x = a->data();
      if (!std::all_of(x, x + a->size(),
                       [](double v) { return std::isfinite(v); })) {
        throw py::value_error(std::string(name) + ": not finite (NaN or Inf)");
      }
    }
  }
  auto r = R.unchecked<3>();
  auto s = t.unchecked<2>();
  Poses poses(n);
  for (py::ssize_t k = 0; k < n; ++k) {
    poses[k].R.resize(d, d);
    poses[k].t.resize(d);
    for (int a = 0; a < d; ++a) {
      for (int b = 0; b < d; ++b) poses[k].R(a, b) = r(k, a, b);
      poses[k].t(a) = s(k, a);
    }
  }
  return poses;
}

LandmarkPositions ToLandmarks(const PoseGraph& graph, py::handle landmarks,
                              bool require_finite) {
  const int d = graph.dimension;
  const py::ssize_t L = graph.num_landmarks;
  if (landmarks.is_none()) {
    if (L == 0) return {};
    throw py::value_error("landmarks: the graph has " + std::to_string(L) +
                          " landmarks; pass their positions, shape (" +
                          std::to_string(L) + ", " + std::to_string(d) + ")");
  }
  const DoubleArray p = ToDoubleArray(landmarks, "landmarks", {L, d});
  if (require_finite &&
      !std::all_of(p.data(), p.data() + p.size(),
                   [](double v) { return std::isfinite(v); })) {
    throw py::value_error("landmarks: not finite (NaN or Inf)");
  }
  auto q = p.unchecked<2>();
  LandmarkPositions out(L, Eigen::VectorXd(d));
  for (py::ssize_t k = 0; k < L; ++k) {
    for (int a = 0; a < d; ++a) out[k](a) = q(k, a);
  }
  return out;
}

DoubleArray LandmarksArray(const LandmarkPositions& landmarks, int d) {
  const py::ssize_t L = static_cast<py::ssize_t>(landmarks.size());
  DoubleArray out({L, static_cast<py::ssize_t>(d)});
  auto q = out.mutable_unchecked<2>();
  for (py::ssize_t k = 0; k < L; ++k) {
    for (int a = 0; a < d; ++a) q(k, a) = landmarks[k](a);
  }
  return out;
}

DoubleArray RotationsArray(const Poses& poses, int d) {
  const py::ssize_t n = static_cast<py::ssize_t>(poses.size());
  DoubleArray out(
      {n, static_cast<py::ssize_t>(d), static_cast<py::ssize_t>(d)});
  auto r = out.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < n; ++k) {
    for (int a = 0; a < d; ++a) {
      for (int b = 0; b < d; ++b) r(k, a, b) = poses[k].R(a, b);
    }
  }
  return out;
}

DoubleArray TranslationsArray(const Poses& poses, int d) {
  const py::ssize_t n = static_cast<py::ssize_t>(poses.size());
  DoubleArray out({n, static_cast<py::ssize_t>(d)});
  auto t = out.mutable_unchecked<2>();
  for (py::ssize_t k = 0; k < n; ++k) {
    for (int a = 0; a < d; ++a) t(k, a) = poses[k].t(a);
  }
  return out;
}

py::object PosesTuple(const Poses& poses, int d) {
  if (poses.empty()) return py::none();
  return py::make_tuple(RotationsArray(poses, d), TranslationsArray(poses, d));
}

}  // namespace ceres_sesync::python
