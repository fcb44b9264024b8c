// numpy <-> the library's pose types. Rotations are (n, d, d) arrays with
// rotations[k][a][b] = R_k(a, b), translations (n, d) arrays, both float64 in
// the graph's dense pose order.

#ifndef CERES_SESYNC_PYTHON_SRC_ARRAYS_H_
#define CERES_SESYNC_PYTHON_SRC_ARRAYS_H_

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style>;

// `value` as a C-contiguous float64 array of the given shape (-1: any
// length); ValueError naming `name` and both shapes otherwise.
DoubleArray ToDoubleArray(py::handle value, const std::string& name,
                          const std::vector<py::ssize_t>& shape);

// `value` as int64 indices of shape (m,) (m = -1: any); the array must hold
// integers (not floats). ValueError naming `name` otherwise.
py::array_t<int64_t, py::array::c_style> ToIndexArray(py::handle value,
                                                      const std::string& name,
                                                      py::ssize_t m);

// Poses from (n, d, d) rotations and (n, d) translations (d and n from
// `graph`). With require_finite, NaN or Inf raise ValueError; values are not
// checked otherwise.
Poses ToPoses(const PoseGraph& graph, py::handle rotations,
              py::handle translations, bool require_finite = false);

// Landmark positions from an (L, d) array (L and d from `graph`; None is
// accepted for a graph without landmarks).
LandmarkPositions ToLandmarks(const PoseGraph& graph, py::handle landmarks,
                              bool require_finite = false);
// (L, d) landmark positions as a new array.
DoubleArray LandmarksArray(const LandmarkPositions& landmarks, int d);

// The rotations / translations of `poses` as new arrays.
DoubleArray RotationsArray(const Poses& poses, int d);
DoubleArray TranslationsArray(const Poses& poses, int d);
// (rotations, translations), or None if `poses` is empty.
py::object PosesTuple(const Poses& poses, int d);

}  // namespace ceres_sesync::python

#endif  // CERES_SESYNC_PYTHON_SRC_ARRAYS_H_
