// Binding the fields of the C++ option and summary structs to Python in one
// place per struct, one line per field:
//
//   py::class_<SolverOptions> cls(m, "SolverOptions");
//   Fields(cls).rw("max_rank", &SolverOptions::max_rank)
//              .rw("seed", &SolverOptions::seed) ...;
//
// Every bound name is recorded in the class attribute `_fields` (a list; a
// derived class starts from its base's). `_fields` drives the keyword
// arguments of solve()/certify()/... (ApplyKeywords), as_dict() and repr in
// the Python layer, and python/tests/test_bindings_complete.py checks it
// against the fields declared in the C++ headers, so that a field added in
// C++ without its line here fails the tests.

#ifndef CERES_SESYNC_PYTHON_SRC_FIELDS_H_
#define CERES_SESYNC_PYTHON_SRC_FIELDS_H_

#include <pybind11/pybind11.h>

#include <string>

namespace ceres_sesync::python {

namespace py = pybind11;

template <typename Class>
class Fields {
 public:
  using T = typename Class::type;

  explicit Fields(Class& cls) : cls_(cls) {
    py::list names;
    if (py::hasattr(cls_, "_fields")) {
      for (py::handle name : cls_.attr("_fields")) names.append(name);
    }
    cls_.attr("_fields") = names;
  }

  // A read-write data member.
  template <typename C, typename M>
  Fields& rw(const char* name, M C::*member, const char* doc = "") {
    cls_.def_readwrite(name, member, doc);
    return Add(name);
  }
  // A read-only data member.
  template <typename C, typename M>
  Fields& ro(const char* name, const M C::*member, const char* doc = "") {
    cls_.def_readonly(name, member, doc);
    return Add(name);
  }
  // A read-only value computed from the object (a field whose Python form
  // differs from the C++ one: a status string, numpy arrays, None for
  // "absent").
  template <typename Getter>
  Fields& get(const char* name, Getter&& getter, const char* doc = "") {
    cls_.def_property_readonly(name, std::forward<Getter>(getter), doc);
    return Add(name);
  }

 private:
  Fields& Add(const char* name) {
    cls_.attr("_fields").attr("append")(name);
    return *this;
  }

  Class& cls_;
};

// Sets the attributes `kwargs` on `target` (an object of a class with
// `_fields`). Unknown names raise TypeError("WHERE() got an unexpected
// keyword argument 'NAME'"); an unknown enum name raises ValueError listing
// the valid ones; a value of the wrong type raises TypeError naming the
// field. A dict given for a field that is itself such an object (e.g.
// CertifyOptions.solver_options) is applied to it recursively.
void ApplyKeywords(py::handle target, const py::dict& kwargs,
                   const std::string& where);

}  // namespace ceres_sesync::python

#endif  // CERES_SESYNC_PYTHON_SRC_FIELDS_H_
