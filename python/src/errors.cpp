// kelp's exceptions in Python, mirroring the C++ hierarchy (include/kelp/core/error.hpp):
//   kelp::error            -> kelp.Error            (a RuntimeError, as kelp::error is a
//                                                     std::runtime_error)
//   kelp::invalid_argument -> kelp.InvalidArgument  (kelp.Error and ValueError)
//   kelp::numerical_error  -> kelp.NumericalError   (kelp.Error, so a RuntimeError)
//   kelp::sim::scenario_error -> kelp.ScenarioError (kelp.InvalidArgument)
//   kelp::sim::state_error    -> kelp.StateError    (kelp.InvalidArgument)
// each carrying the C++ message (what()).
#include <Python.h>

#include "bindings.hpp"
#include "kelp/core/error.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/state_error.hpp"

namespace kelp_python {

namespace {

// The classes, created once by bind_errors (owned by the module; these are borrowed).
PyObject* error_type = nullptr;
PyObject* invalid_argument_type = nullptr;
PyObject* numerical_error_type = nullptr;
PyObject* scenario_error_type = nullptr;
PyObject* state_error_type = nullptr;

PyObject* new_exception(py::module_& m, const char* name, const char* doc, py::tuple bases) {
  const std::string qualified = std::string("kelp.") + name;
  PyObject* t = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (t == nullptr) throw py::error_already_set();
  m.add_object(name, py::reinterpret_borrow<py::object>(t));
  return t;
}

}  // namespace

void bind_errors(py::module_& m) {
  error_type = new_exception(m, "Error",
                             "Base of every error kelp raises (C++ kelp::error, a "
                             "std::runtime_error): a RuntimeError.",
                             py::make_tuple(py::handle(PyExc_RuntimeError)));
  invalid_argument_type = new_exception(
      m, "InvalidArgument",
      "A value kelp cannot use (NaN, a negative mass, an array of the wrong shape, an unknown "
      "scenario key...): a ValueError (and a kelp.Error). The message names the offending "
      "field (C++ kelp::invalid_argument).",
      py::make_tuple(py::handle(error_type), py::handle(PyExc_ValueError)));
  numerical_error_type = new_exception(
      m, "NumericalError",
      "A computation could not proceed from a valid input (e.g. a step produced a non-finite "
      "state; the state passed in is left unchanged): a RuntimeError (C++ "
      "kelp::numerical_error).",
      py::make_tuple(py::handle(error_type)));
  scenario_error_type = new_exception(
      m, "ScenarioError",
      "A scenario kelp::sim refuses: the message names the file (or '(dict)') and the JSON path "
      "of the offending field (C++ kelp::sim::scenario_error). A kelp.InvalidArgument.",
      py::make_tuple(py::handle(invalid_argument_type)));
  state_error_type = new_exception(
      m, "StateError",
      "A state that cannot be saved or loaded (kelp.save_state, kelp.load_state, pickle): a "
      "truncated or corrupted file, one of another kind or system, NaN where a step refuses it. "
      "The message names the input and what is wrong (C++ kelp::sim::state_error). A "
      "kelp.InvalidArgument.",
      py::make_tuple(py::handle(invalid_argument_type)));

  // Tried before pybind11's own translations (the latest registered is tried first), so the
  // most derived C++ type is caught first here.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const kelp::sim::scenario_error& e) {
      PyErr_SetString(scenario_error_type, e.what());
    } catch (const kelp::sim::state_error& e) {
      PyErr_SetString(state_error_type, e.what());
    } catch (const kelp::invalid_argument& e) {
      PyErr_SetString(invalid_argument_type, e.what());
    } catch (const kelp::numerical_error& e) {
      PyErr_SetString(numerical_error_type, e.what());
    } catch (const kelp::error& e) {
      PyErr_SetString(error_type, e.what());
    }
  });

  // For tests: raise each kind from C++, to check the translation (and its message).
  m.def(
      "_raise_for_test",
      [](const std::string& kind, const std::string& message) {
        if (kind == "invalid_argument") throw kelp::invalid_argument(message);
        if (kind == "numerical_error") throw kelp::numerical_error(message);
        if (kind == "scenario_error") throw kelp::sim::scenario_error(message);
        if (kind == "state_error") throw kelp::sim::state_error(message);
        if (kind == "error") throw kelp::error(message);
        throw std::logic_error("unknown kind " + kind);
      },
      py::arg("kind"), py::arg("message"),
      "Raises the C++ exception `kind` ('invalid_argument', 'numerical_error', "
      "'scenario_error', 'state_error', 'error') with `message` (tests only).");
}

}  // namespace kelp_python
