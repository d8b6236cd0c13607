// The gym-style environment's C++ core (kelp::sim::TetheredPairEnv) as kelp._kelp.PairEnvCore;
// kelp.TetheredPairEnv (python/kelp/learning.py) gives it gymnasium's API.
#include <pybind11/numpy.h>

#include <cstdint>
#include <memory>
#include <string>

#include "bindings.hpp"
#include "kelp/sim/pair_env.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp_python {

void bind_learning(py::module_& m) {
  namespace ks = kelp::sim;
  using PairEnv = ks::TetheredPairEnv;
  py::class_<PairEnv>(m, "PairEnvCore", R"(The C++ core of kelp.TetheredPairEnv (use that instead).

A scenario's world whose ROV (and optionally boat) is flown by an action through the ROV
controller's thrust allocation, with a 20-entry observation and the reward
-path_weight * path error - energy_weight * battery energy (see kelp.TetheredPairEnv).)")
      .def(py::init([](const std::string& text, const std::string& name, double control_period,
                       bool asv_action, double max_path_error, double path_weight,
                       double energy_weight) {
             ks::PairEnvOptions o;
             o.control_period = control_period;
             o.asv_action = asv_action;
             o.max_path_error = max_path_error;
             o.path_weight = path_weight;
             o.energy_weight = energy_weight;
             return std::make_unique<PairEnv>(ks::parse_scenario(text, name), o);
           }),
           py::arg("scenario_json"), py::arg("scenario_name"), py::arg("control_period") = 0.1,
           py::arg("asv_action") = false, py::arg("max_path_error") = 20.0,
           py::arg("path_weight") = 1.0, py::arg("energy_weight") = 0.01,
           "An environment over the scenario in JSON text (its name is used in errors).")
      .def("reset", &PairEnv::reset, py::arg("seed"),
           "New episode: the scenario's world with `seed` as its sea's seed.")
      .def(
          "step",
          [](PairEnv& e, py::array_t<double, py::array::c_style | py::array::forcecast> action) {
            if (action.ndim() != 1 || action.shape(0) != e.action_size())
              throw kelp::invalid_argument("TetheredPairEnv.step: the action must have shape (" +
                                           std::to_string(e.action_size()) + ",), got ndim " +
                                           std::to_string(action.ndim()) + ", size " +
                                           std::to_string(action.size()));
            const double r = e.step(action.data());
            return py::make_tuple(r, e.terminated(), e.truncated());
          },
          py::arg("action"),
          "Applies the action for one control period; returns (reward, terminated, truncated).")
      .def(
          "observation",
          [](const PairEnv& e) {
            py::array_t<double> o(PairEnv::observation_size);
            std::copy(e.observation().begin(), e.observation().end(), o.mutable_data());
            return o;
          },
          "A copy of the current observation (20 floats).")
      .def_property_readonly("action_size", &PairEnv::action_size, "Entries of an action.")
      .def_property_readonly_static(
          "observation_size", [](py::object) { return PairEnv::observation_size; },
          "Entries of an observation.")
      .def_property_readonly_static(
          "action_scale",
          [](py::object) {
            py::tuple t(PairEnv::action_scale.size());
            for (std::size_t i = 0; i < PairEnv::action_scale.size(); ++i)
              t[i] = PairEnv::action_scale[i];
            return t;
          },
          "The ROV wrench an action entry of 1 asks for [N, N m] (X, Y, Z, K, M, N).")
      .def_property_readonly("substeps", &PairEnv::substeps, "System steps (10 ms) per step.")
      .def_property_readonly(
          "time", [](const PairEnv& e) { return e.loop().time(); }, "Simulation time [s].")
      .def_property_readonly(
          "path_error", [](const PairEnv& e) { return e.observation()[19]; },
          "The ROV's distance from its survey leg [m].")
      .def_property_readonly("energy_drawn", &PairEnv::energy_drawn,
                             "Energy the ROV's battery delivered since reset [J].")
      .def_property_readonly(
          "saturated", [](const PairEnv& e) { return e.auv_command().saturated; },
          "The ROV's action asked for more than its thrusters give.")
      .def_property_readonly("terminated", &PairEnv::terminated, "The episode terminated.")
      .def_property_readonly("truncated", &PairEnv::truncated, "The episode was truncated.")
      .def_property_readonly("error", &PairEnv::error, "Why a step failed ('' otherwise).")
      .def_property_readonly(
          "auv_position",
          [](const PairEnv& e) {
            const auto& p = e.loop().state().auv.position;
            return py::make_tuple(p.x(), p.y(), p.z());
          },
          "The ROV's position, NED [m].")
      .def(
          "summary",
          [](const PairEnv& e) {
            return py::module_::import("json").attr("loads")(
                kelp::sim::summary_json(e.loop().summary()));
          },
          "The episode's summary so far, as kelp-tethered-pair's summary.json (no wall time).");
}

}  // namespace kelp_python
