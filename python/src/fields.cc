#include "python/src/fields.h"

namespace ceres_sesync::python {
namespace {

std::string TypeName(py::handle value) {
  return py::str(py::type::of(value).attr("__name__"));
}

// ApplyKeywords, with `prefix` naming the enclosing field ("solver_options.")
// in messages.
void Apply(py::handle target, const py::dict& kwargs, const std::string& where,
           const std::string& prefix) {
  const py::object fields = target.attr("_fields");
  for (auto item : kwargs) {
    const std::string key = py::str(item.first);
    if (!fields.contains(py::str(key))) {
      throw py::type_error(where + "() got an unexpected keyword argument '" +
                           prefix + key + "'");
    }
    py::handle value = item.second;
    py::object current = target.attr(key.c_str());
    if (py::isinstance<py::dict>(value) && py::hasattr(current, "_fields")) {
      Apply(current, py::reinterpret_borrow<py::dict>(value), where,
            prefix + key + ".");
      continue;
    }
    try {
      py::setattr(target, key.c_str(), value);
    } catch (py::error_already_set& e) {
      if (!e.matches(PyExc_TypeError)) throw;
      const py::object type = py::type::of(current);
      if (py::hasattr(type, "__members__") && py::isinstance<py::str>(value)) {
        std::string names;
        for (auto member : type.attr("__members__").cast<py::dict>()) {
          names += (names.empty() ? "'" : ", '") +
                   std::string(py::str(member.first)) + "'";
        }
        throw py::value_error(where + "(): " + prefix + key +
                              " must be one of " + names + ", not '" +
                              std::string(py::str(value)) + "'");
      }
      const std::string expected =
          current.is_none() || PyCallable_Check(current.ptr())
              ? "a callable or None"
              : TypeName(current);
      throw py::type_error(where + "(): " + prefix + key + " must be " +
                           expected + ", not " + TypeName(value));
    }
  }
}

}  // namespace

void ApplyKeywords(py::handle target, const py::dict& kwargs,
                   const std::string& where) {
  Apply(target, kwargs, where, "");
}

}  // namespace ceres_sesync::python
