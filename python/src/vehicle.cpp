// kelp.VehicleState, kelp.Vehicle (presets, thrusters, step) and the T200 curves.
#include <pybind11/numpy.h>

#include <limits>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/t200.hpp"
#include "kelp/vehicle/water.hpp"
#include "types.hpp"

namespace kelp_python {

using kelp::vehicle::VehicleStated;

void bind_vehicle(py::module_& m) {
  py::class_<VehicleStated>(
      m, "VehicleState",
      "A vehicle's state: NED position of its body origin [m], attitude (unit quaternion, body "
      "-> NED, in (x, y, z, w) order as scipy's Rotation.from_quat), body velocity nu = (u, v, "
      "w, p, q, r) [m/s, rad/s] and time [s].\n\n"
      "`position`, `attitude` and `nu` are zero-copy, writable numpy views of the state's memory "
      "(writing into them changes the state); each view keeps the state alive. Setting the "
      "property copies the values in.")
      .def(py::init([](py::object position, py::object attitude, py::object nu, double time) {
             VehicleStated s;
             if (!position.is_none()) s.position = vector_arg<3>(position, "position");
             if (!attitude.is_none()) s.attitude.coeffs() = vector_arg<4>(attitude, "attitude");
             if (!nu.is_none()) s.nu = vector_arg<6>(nu, "nu");
             s.time = time;
             return s;
           }),
           py::arg("position") = py::none(), py::arg("attitude") = py::none(),
           py::arg("nu") = py::none(), py::arg("time") = 0.0,
           "A state at `position` (NED [m], default the origin), `attitude` ((x, y, z, w), "
           "default level heading north), `nu` (default at rest) and `time` [s].")
      .def_property(
          "position",
          [](py::object self) {
            return vector_view(self.cast<VehicleStated&>().position.data(), 3, self);
          },
          [](VehicleStated& s, py::handle v) { s.position = vector_arg<3>(v, "position"); },
          "NED position of the body origin [m], shape (3,): a view.")
      .def_property(
          "attitude",
          [](py::object self) {
            return vector_view(self.cast<VehicleStated&>().attitude.coeffs().data(), 4, self);
          },
          [](VehicleStated& s, py::handle v) {
            s.attitude.coeffs() = vector_arg<4>(v, "attitude");
          },
          "Unit quaternion body -> NED as (x, y, z, w), shape (4,): a view (Eigen's storage "
          "order). A step refuses a non-unit one (kelp.InvalidArgument).")
      .def_property(
          "nu",
          [](py::object self) {
            return vector_view(self.cast<VehicleStated&>().nu.data(), 6, self);
          },
          [](VehicleStated& s, py::handle v) { s.nu = vector_arg<6>(v, "nu"); },
          "Body velocity (u, v, w, p, q, r) [m/s, rad/s], shape (6,): a view.")
      .def_readwrite("time", &VehicleStated::time, "Simulation time [s].")
      .def_property(
          "euler",
          [](const VehicleStated& s) {
            return copy_vector(kelp::euler_from_quaternion(s.attitude));
          },
          [](VehicleStated& s, py::handle v) {
            const Eigen::Vector3d e = vector_arg<3>(v, "euler");
            s.attitude = kelp::quaternion_from_euler(e(0), e(1), e(2));
          },
          "(roll, pitch, yaw) [rad], ZYX convention (Fossen 2021, eq. 2.18): a copy; setting it "
          "sets the attitude.")
      .def(
          "rotation", [](const VehicleStated& s) { return copy_matrix(s.rotation()); },
          "Rotation matrix body -> NED, shape (3, 3) (a copy).")
      .def(
          "point_position",
          [](const VehicleStated& s, py::handle r) {
            return copy_vector(s.point_position(vector_arg<3>(r, "r_body")));
          },
          py::arg("r_body"), "NED position [m] of the body-fixed point `r_body` (body axes [m]).")
      .def(
          "copy", [](const VehicleStated& s) { return s; }, "An independent copy.")
      .def("__copy__", [](const VehicleStated& s) { return s; })
      .def(
          "__deepcopy__", [](const VehicleStated& s, py::dict) { return s; }, py::arg("memo"))
      .def("__repr__", [](const VehicleStated& s) {
        char b[200];
        std::snprintf(
            b, sizeof b, "VehicleState(position=[%g, %g, %g], nu=[%g, %g, %g, ...], time=%g)",
            s.position(0), s.position(1), s.position(2), s.nu(0), s.nu(1), s.nu(2), s.time);
        return std::string(b);
      });

  py::class_<Vehicle>(
      m, "Vehicle",
      "A Fossen 6-DOF vehicle (M nu_dot + C(nu) nu + D(nu) nu + g(eta) = tau + tau_ext, Fossen "
      "2021, eq. 6.5) with its thrusters: a preset (kelp.Vehicle.bluerov2_heavy(), "
      "kelp.Vehicle.blueboat()), its model built once (M and its factorisation) and its step "
      "buffers. Step a kelp.VehicleState with step(); build thrust wrenches with wrench().")
      .def_static(
          "bluerov2_heavy",
          [](double density, double gravity) {
            return std::make_unique<Vehicle>(
                kelp::vehicle::bluerov2_heavy<double>(density, gravity));
          },
          py::arg("density") = kelp::seawater_density, py::arg("gravity") = kelp::standard_gravity,
          "The BlueROV2 Heavy (von Benzon et al. 2022, Table A1) with 8 T200 thrusters in "
          "ArduSub's motor order, in water of `density` [kg/m^3] under `gravity` [m/s^2].")
      .def_static(
          "blueboat",
          [](double density, double gravity) {
            return std::make_unique<Vehicle>(kelp::vehicle::blueboat<double>(density, gravity));
          },
          py::arg("density") = kelp::seawater_density, py::arg("gravity") = kelp::standard_gravity,
          "The BlueBoat ASV with its 2 T200 thrusters (port, starboard), in water of `density` "
          "[kg/m^3] under `gravity` [m/s^2].")
      .def_property_readonly(
          "name", [](const Vehicle& v) { return v.preset.name; }, "The preset's name.")
      .def_property_readonly(
          "mass", [](const Vehicle& v) { return v.preset.parameters.mass; },
          "Rigid-body mass [kg].")
      .def_property_readonly(
          "weight", [](const Vehicle& v) { return v.model.weight(); }, "W = m g [N].")
      .def_property_readonly(
          "buoyancy", [](const Vehicle& v) { return v.model.buoyancy(); }, "B = rho g V [N].")
      .def_property_readonly(
          "mass_matrix", [](const Vehicle& v) { return copy_matrix(v.model.mass_matrix()); },
          "M = M_RB + M_A, shape (6, 6) (a copy).")
      .def_property_readonly(
          "thruster_count", [](const Vehicle& v) { return v.thrusters.size(); },
          "Number of thrusters.")
      .def_property_readonly(
          "thruster_positions",
          [](py::object self) {
            const Vehicle& v = self.cast<const Vehicle&>();
            return points_view(v.thrusters.positions().data(), v.thrusters.size(), self, false);
          },
          "Thruster positions r_i (body axes from the CO [m]), shape (n, 3): a read-only view.")
      .def_property_readonly(
          "thruster_directions",
          [](py::object self) {
            const Vehicle& v = self.cast<const Vehicle&>();
            return points_view(v.thrusters.directions().data(), v.thrusters.size(), self, false);
          },
          "Unit thrust directions d_i of a positive command (body axes), shape (n, 3): a "
          "read-only view.")
      .def(
          "wrench",
          [](const Vehicle& v, py::handle thrust) {
            return copy_vector(
                v.thrusters.wrench(vector_arg(thrust, v.thrusters.size(), "thrust")));
          },
          py::arg("thrust"),
          "Body wrench tau (X, Y, Z, K, M, N) [N, N m], shape (6,), of the thrusters' forces "
          "`thrust` [N], shape (n,).")
      .def(
          "step",
          [](Vehicle& v, VehicleStated& state, double dt, py::handle tau, py::handle tau_ext,
             py::handle current, const kelp::environment::Environmentd* env) {
            kelp::vehicle::VehicleInputsd in;
            if (!tau.is_none()) in.tau = vector_arg<6>(tau, "tau");
            if (!tau_ext.is_none()) in.tau_ext = vector_arg<6>(tau_ext, "tau_ext");
            if (env != nullptr) {
              KELP_CHECK(current.is_none(),
                         "Vehicle.step: give either `current` or `environment`, not both");
              kelp::vehicle::check_same_water(v.preset.parameters, *env, v.preset.name);
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(v.mutex);
              kelp::vehicle::step_rk4(v.model, v.workspace, *env, state, in, dt);
              return;
            }
            const Eigen::Vector3d c = current.is_none()
                                          ? Eigen::Vector3d::Zero()
                                          : Eigen::Vector3d(vector_arg<3>(current, "current"));
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(v.mutex);
            kelp::vehicle::step_rk4(v.model, v.workspace, state, in, dt, c);
          },
          py::arg("state"), py::arg("dt"), py::arg("tau") = py::none(),
          py::arg("tau_ext") = py::none(), py::arg("current") = py::none(),
          py::arg("environment") = py::none(),
          "Advances `state` in place by one classical RK4 step of `dt` [s] under the control "
          "wrench `tau` and any other wrench `tau_ext` (body axes [N, N m], shape (6,), held "
          "over the step; default zero), in still water, a uniform NED `current` [m/s] or a "
          "kelp.Environment (waves, current, wind, free surface; its water must be the "
          "vehicle's). Raises kelp.InvalidArgument (bad dt, shapes, a non-finite state, a "
          "non-unit attitude) or kelp.NumericalError (a non-finite result); the state is then "
          "unchanged.");

  m.def("t200_thrust", py::vectorize([](double command, double voltage) {
          return kelp::vehicle::t200_thrust(command, voltage);
        }),
        py::arg("command"), py::arg("voltage") = kelp::vehicle::t200_nominal_voltage,
        "A T200's thrust [N] at the normalised command in [-1, 1] and supply `voltage` [V] "
        "(Blue Robotics' published performance data; kelp/vehicle/t200.hpp), elementwise over "
        "numpy arrays.");
  m.def("t200_current", py::vectorize([](double command, double voltage) {
          return kelp::vehicle::t200_current(command, voltage);
        }),
        py::arg("command"), py::arg("voltage") = kelp::vehicle::t200_nominal_voltage,
        "A T200's current draw [A] at `command` and `voltage` [V], elementwise.");
}

}  // namespace kelp_python
