// kelp.catenary: the paper's static catenary between two points (kelp/tether/catenary.hpp).
#include <limits>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/tether/catenary.hpp"

namespace kelp_python {

namespace kt = kelp::tether;

void bind_catenary(py::module_& m) {
  py::class_<kt::CatenaryShaped>(
      m, "Catenary",
      "A solved static catenary (kelp.catenary()): z(x) = a cosh((x - c)/a) - a cosh(c/a) in "
      "the vertical plane through both ends (x horizontal from the start, z up), with H = a w. "
      "Physically possible geometry never raises: `status` says what happened ('converged', "
      "'taut', 'vertical', 'invalid_input', 'max_iterations'). Forces are NED with x from the "
      "start towards the end.")
      .def_property_readonly(
          "a", [](const kt::CatenaryShaped& s) { return s.result().a; },
          "Catenary parameter a = H/w [m] (inf when taut, 0 when vertical, NaN when invalid).")
      .def_property_readonly(
          "c", [](const kt::CatenaryShaped& s) { return s.result().c; },
          "Horizontal position of the vertex from the start [m] (NaN when taut or invalid).")
      .def_property_readonly(
          "status",
          [](const kt::CatenaryShaped& s) { return std::string(kt::to_string(s.status())); },
          "'converged', 'taut', 'vertical', 'invalid_input' or 'max_iterations'.")
      .def_property_readonly(
          "ok", [](const kt::CatenaryShaped& s) { return s.result().ok(); },
          "True when a, c describe the line (converged or vertical).")
      .def_property_readonly(
          "iterations", [](const kt::CatenaryShaped& s) { return s.result().iterations; },
          "Iterations of the 1-D solve.")
      .def_property_readonly(
          "residual", [](const kt::CatenaryShaped& s) { return s.result().residual; },
          "max(|R1|, |R2|)/L of the paper's two equations at a, c.")
      .def_property_readonly("horizontal_tension", &kt::CatenaryShaped::horizontal_tension,
                             "H = a |w| [N], the same all along the line.")
      .def_property_readonly(
          "taut_tension", [](const kt::CatenaryShaped& s) { return s.result().taut_tension; },
          "EA (chord - L)/L of a taut line [N] (0 unless taut with EA > 0).")
      .def_property_readonly(
          "tension_start", [](const kt::CatenaryShaped& s) { return s.force_on_start().norm(); },
          "Tension at the start end [N].")
      .def_property_readonly(
          "tension_end", [](const kt::CatenaryShaped& s) { return s.force_on_end().norm(); },
          "Tension at the end [N].")
      .def_property_readonly(
          "vertical_force_start",
          [](const kt::CatenaryShaped& s) { return s.force_on_start().z(); },
          "Vertical pull of the line on the start end, positive down [N].")
      .def_property_readonly(
          "vertical_force_end", [](const kt::CatenaryShaped& s) { return s.force_on_end().z(); },
          "Vertical pull of the line on the end, positive down [N].")
      .def_property_readonly(
          "force_on_start",
          [](const kt::CatenaryShaped& s) { return copy_vector(s.force_on_start()); },
          "Force of the line on the start end, NED [N], shape (3,).")
      .def_property_readonly(
          "force_on_end", [](const kt::CatenaryShaped& s) { return copy_vector(s.force_on_end()); },
          "Force of the line on the end, NED [N], shape (3,).")
      .def_property_readonly("on_seabed", &kt::CatenaryShaped::on_seabed,
                             "True when part of the line rests on the seabed.")
      .def(
          "points",
          [](const kt::CatenaryShaped& s, int n) {
            KELP_CHECK(n >= 2, "points: n must be >= 2");
            py::array_t<double> out({py::ssize_t(n), py::ssize_t(3)});
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < n; ++i) {
              const Eigen::Vector3d p = s.point_at(s.length() * i / (n - 1));
              for (int k = 0; k < 3; ++k) o(i, k) = p(k);
            }
            return out;
          },
          py::arg("n") = 50,
          "`n` points of the line, NED [m] (start at the origin, z down), evenly spaced in arc "
          "length, shape (n, 3). Raises kelp.InvalidArgument for an unsolved line.")
      .def("tension_at", &kt::CatenaryShaped::tension_at, py::arg("s"),
           "Tension [N] at arc length `s` [m] from the start.")
      .def("__repr__", [](const kt::CatenaryShaped& s) {
        return "Catenary(status='" + std::string(kt::to_string(s.status())) +
               "', a=" + std::to_string(s.result().a) + ", c=" + std::to_string(s.result().c) +
               ", H=" + std::to_string(s.horizontal_tension()) + ")";
      });

  m.def(
      "catenary",
      [](double horizontal, double vertical, double length, double weight_per_length, double EA,
         double tolerance, int max_iterations, double seabed_depth) {
        kt::CatenaryOptionsd o;
        o.EA = EA;
        o.tolerance = tolerance;
        o.max_iterations = max_iterations;
        o.seabed_depth = seabed_depth;
        return kt::catenary_between<double>(Eigen::Vector3d::Zero(),
                                            Eigen::Vector3d(horizontal, 0.0, -vertical), length,
                                            weight_per_length, o);
      },
      py::kw_only(), py::arg("horizontal"), py::arg("vertical"), py::arg("length"),
      py::arg("weight_per_length"), py::arg("EA") = 0.0, py::arg("tolerance") = 1e-14,
      py::arg("max_iterations") = 30,
      py::arg("seabed_depth") = std::numeric_limits<double>::infinity(),
      "The static catenary of a line of unstretched `length` L [m] and submerged weight per "
      "length w [N/m] (< 0: buoyant, arching up) between a start end and an end `horizontal` D "
      "[m] away and `vertical` dz [m] higher (z up): a, c solve a[cosh((D - c)/a) - cosh(c/a)] "
      "= dz and a[sinh((D - c)/a) + sinh(c/a)] = L by the analytic reduction sqrt(L^2 - dz^2) = "
      "2a sinh(D/(2a)). `EA` [N] gives a taut line its tension; `seabed_depth` [m below the "
      "start] a flat seabed. Returns a kelp.Catenary (a, c, status, tensions); never raises for "
      "geometry: check `status`.");
}

}  // namespace kelp_python
