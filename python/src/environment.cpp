// kelp.Environment: sea presets, sample() and surface_elevation() over arrays of points.
#include <pybind11/numpy.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"

namespace kelp_python {

namespace {

using Env = kelp::environment::Environmentd;
namespace ke = kelp::environment;

ke::WaveStretching stretching_of(const std::string& name) {
  if (name == "vertical") return ke::WaveStretching::vertical;
  if (name == "wheeler") return ke::WaveStretching::wheeler;
  kelp::detail::throw_invalid_argument("stretching: expected \"vertical\" or \"wheeler\", got \"" +
                                       name + "\"");
}

Env make(const ke::SeaState& sea, std::uint64_t seed, int wave_components, double ramp,
         double seabed_depth, const std::string& stretching = "vertical") {
  ke::SeaStateOptions o;
  o.seed = seed;
  o.wave_components = wave_components;
  o.ramp = ramp;
  o.seabed_depth = seabed_depth;
  o.stretching = stretching_of(stretching);
  return ke::make_environment<double>(sea, o);
}

/// One regular wave from a dict with the scenario's keys: "height", "period" or "wavelength",
/// "direction", "phase" (the environment checks the values).
ke::RegularWave regular_wave(py::handle h) {
  if (!py::isinstance<py::dict>(h))
    kelp::detail::throw_invalid_argument(
        "regular: expected a dict {\"height\": m, \"period\": s (or \"wavelength\": m), "
        "\"direction\": rad, \"phase\": rad} or a list of them");
  ke::RegularWave w;
  for (const auto& item : py::reinterpret_borrow<py::dict>(h)) {
    const std::string key = py::str(item.first);
    double value = 0.0;
    try {
      value = item.second.cast<double>();
    } catch (const py::cast_error&) {
      kelp::detail::throw_invalid_argument("regular." + key + " must be a number");
    }
    if (key == "height")
      w.height = value;
    else if (key == "period")
      w.period = value;
    else if (key == "wavelength")
      w.wavelength = value;
    else if (key == "direction")
      w.direction = value;
    else if (key == "phase")
      w.phase = value;
    else
      kelp::detail::throw_invalid_argument(
          "regular: unknown key \"" + key +
          "\" (expected height, period, wavelength, direction, phase)");
  }
  return w;
}

/// None, one dict, or a list of dicts: the regular waves.
std::vector<ke::RegularWave> regular_waves(py::handle h) {
  std::vector<ke::RegularWave> out;
  if (h.is_none()) return out;
  if (py::isinstance<py::dict>(h)) {
    out.push_back(regular_wave(h));
  } else if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    for (py::handle w : h) out.push_back(regular_wave(w));
  } else {
    regular_wave(h);  // throws, saying what is expected
  }
  return out;
}

ke::SeaState preset(const std::string& sea) {
  if (sea == "calm") return ke::presets::calm();
  if (sea == "moderate") return ke::presets::moderate();
  if (sea == "rough") return ke::presets::rough();
  kelp::detail::throw_invalid_argument("sea: expected \"calm\", \"moderate\" or \"rough\", got \"" +
                                       sea + "\"");
}

}  // namespace

void bind_environment(py::module_& m) {
  const double inf = std::numeric_limits<double>::infinity();
  py::class_<Env>(
      m, "Environment",
      "The sea a simulation runs in: water and air densities, gravity, seabed, current, waves "
      "(a JONSWAP sea of `wave_components` components: elevation, orbital velocity and "
      "acceleration decaying with depth) and wind with gusts. World frame NED (z down, still "
      "water at z = 0), SI units, time in s.\n\n"
      "Build one with kelp.Environment() (still water), kelp.Environment.preset('moderate', "
      "seed=1) (the paper's calm / moderate / rough seas) or kelp.Environment.sea_state(...) "
      "(any sea). Query it with sample(points, t) and surface_elevation(points, t), "
      "vectorised over (n, 3) arrays of points.")
      .def(py::init<>(),
           "Still water (seawater, standard gravity, no seabed, no current, waves or wind).")
      .def_static(
          "preset",
          [](const std::string& sea, std::uint64_t seed, int wave_components, double ramp,
             double seabed_depth, const std::string& stretching) {
            return make(preset(sea), seed, wave_components, ramp, seabed_depth, stretching);
          },
          py::arg("sea") = "moderate", py::arg("seed") = 1, py::arg("wave_components") = 64,
          py::arg("ramp") = 0.0, py::arg("seabed_depth") = inf, py::arg("stretching") = "vertical",
          "One of the paper's seas: 'calm' (nothing), 'moderate' (Hs 3 m, wind 3 m/s, current "
          "0.5 m/s) or 'rough' (Hs 4.5 m, wind 4.5 m/s, current 1 m/s), Tp = 4.5 sqrt(Hs), "
          "its waves and gusts drawn from `seed`, brought in over `ramp` s, over a flat seabed "
          "at `seabed_depth` m (default none). `stretching`: the wave kinematics near the "
          "surface, 'vertical' (those of the mean level above it; the default) or 'wheeler' "
          "(Wheeler 1970: the wetted column stretched onto the mean one; docs/equations.md, "
          "section 2).")
      .def_static(
          "sea_state",
          [](double hs, double tp, double gamma, double wave_direction, double wind_speed,
             double wind_direction, double current_speed, double current_direction,
             std::uint64_t seed, int wave_components, double ramp, double seabed_depth,
             py::handle regular, const std::string& stretching) {
            ke::SeaState s;
            s.regular_waves = regular_waves(regular);
            s.significant_height = hs;
            s.peak_period = tp;
            s.peak_enhancement =
                std::isnan(gamma) ? (hs > 0 ? ke::dnv_peak_enhancement(hs, tp) : 1.0) : gamma;
            s.wave_direction = wave_direction;
            s.wind_speed = wind_speed;
            s.wind_direction = wind_direction;
            s.current_speed = current_speed;
            s.current_direction = current_direction;
            return make(s, seed, wave_components, ramp, seabed_depth, stretching);
          },
          py::arg("significant_height") = 0.0, py::arg("peak_period") = 8.0,
          py::arg("peak_enhancement") = std::numeric_limits<double>::quiet_NaN(),
          py::arg("wave_direction") = 0.0, py::arg("wind_speed") = 0.0,
          py::arg("wind_direction") = 0.0, py::arg("current_speed") = 0.0,
          py::arg("current_direction") = 0.0, py::arg("seed") = 1, py::arg("wave_components") = 64,
          py::arg("ramp") = 0.0, py::arg("seabed_depth") = inf, py::arg("regular") = py::none(),
          py::arg("stretching") = "vertical",
          "Any sea: JONSWAP waves of significant height Hs [m] and peak period Tp [s] (peak "
          "enhancement gamma: default DNV's for Hs, Tp), travelling towards `wave_direction` "
          "(NED azimuth [rad]); mean wind [m/s] and current [m/s] towards their directions. "
          "`regular`: a regular (Airy) wave, a dict {'height': m, 'period': s (or "
          "'wavelength': m, not both), 'direction': rad, 'phase': rad}, or a list of them, on "
          "top of the JONSWAP sea (alone with significant_height=0): elevation "
          "height/2 cos(k (x cos(direction) + y sin(direction)) - omega t + phase), dispersion "
          "for `seabed_depth`. `stretching`: 'vertical' (default) or 'wheeler' (see preset).")
      .def_property_readonly("water_density", &Env::water_density, "rho [kg/m^3].")
      .def_property_readonly("air_density", &Env::air_density, "rho_air [kg/m^3].")
      .def_property_readonly("gravity", &Env::gravity, "g [m/s^2].")
      .def_property_readonly("seabed_depth", &Env::seabed_depth,
                             "NED z of the seabed [m] (inf: none).")
      .def_property_readonly("ramp", &Env::ramp, "Start-up ramp T [s] (0: none).")
      .def(
          "sample",
          [](const Env& e, py::handle points, double t, bool with_wind) {
            bool single = false;
            const DoubleArray p = points_arg(points, 3, "points", single);
            const py::ssize_t n = single ? 1 : p.shape(0);
            py::array_t<double> cur({n, py::ssize_t(3)}), vel({n, py::ssize_t(3)}),
                acc({n, py::ssize_t(3)}), wind({n, py::ssize_t(3)}), slope({n, py::ssize_t(2)}),
                eta(n);
            double *pc = cur.mutable_data(), *pv = vel.mutable_data(), *pa = acc.mutable_data(),
                   *pw = wind.mutable_data(), *ps = slope.mutable_data(), *pe = eta.mutable_data();
            const double* pp = p.data();
            {
              py::gil_scoped_release release;
              for (py::ssize_t i = 0; i < n; ++i) {
                const ke::EnvironmentSample<double> s = e.sample(
                    Eigen::Vector3d(pp[3 * i], pp[3 * i + 1], pp[3 * i + 2]), t, with_wind);
                Eigen::Map<Eigen::Vector3d>(pc + 3 * i) = s.current;
                Eigen::Map<Eigen::Vector3d>(pv + 3 * i) = s.wave_velocity;
                Eigen::Map<Eigen::Vector3d>(pa + 3 * i) = s.wave_acceleration;
                Eigen::Map<Eigen::Vector3d>(pw + 3 * i) = s.wind;
                Eigen::Map<Eigen::Vector2d>(ps + 2 * i) = s.surface_slope;
                pe[i] = s.surface_elevation;
              }
            }
            py::dict d;
            const auto one = [&](py::array a) -> py::object {
              return single ? py::object(a[py::int_(0)]) : py::object(a);
            };
            d["current"] = one(cur);
            d["wave_velocity"] = one(vel);
            d["wave_acceleration"] = one(acc);
            d["surface_elevation"] = single ? py::object(py::float_(pe[0])) : py::object(eta);
            d["surface_slope"] = one(slope);
            d["wind"] = one(wind);
            return d;
          },
          py::arg("points"), py::arg("t"), py::arg("with_wind") = true,
          "Everything at NED `points` [m] (shape (n, 3), or (3,) for one point) and time `t` "
          "[s]: a dict of numpy arrays 'current', 'wave_velocity', 'wave_acceleration', 'wind' "
          "(n, 3) [m/s, m/s^2], 'surface_elevation' (n,) [m, positive up] and 'surface_slope' "
          "(n, 2) at the points' (x, y). Wave kinematics are zero above the free surface; wind "
          "is at 10 m (zero with with_wind=False, which saves the gust sum). A point with a NaN or "
          "infinite coordinate raises kelp.InvalidArgument.")
      .def(
          "surface_elevation",
          [](const Env& e, py::handle points, double t) -> py::object {
            DoubleArray p = as_doubles(points, "points");
            const py::ssize_t c = p.ndim() >= 1 ? p.shape(p.ndim() - 1) : 0;
            if (p.ndim() < 1 || p.ndim() > 2 || (c != 2 && c != 3))
              kelp::detail::throw_invalid_argument(
                  "points: expected shape (n, 2), (n, 3), (2,) or (3,), got " + shape_text(p));
            const py::ssize_t n = p.ndim() == 1 ? 1 : p.shape(0);
            py::array_t<double> out(n);
            double* po = out.mutable_data();
            const double* pp = p.data();
            {
              py::gil_scoped_release release;
              for (py::ssize_t i = 0; i < n; ++i)
                po[i] = e.surface_elevation(pp[c * i], pp[c * i + 1], t);
            }
            if (p.ndim() == 1) return py::float_(po[0]);
            return std::move(out);
          },
          py::arg("points"), py::arg("t"),
          "Free-surface elevation zeta [m], positive up, at the (x, y) of `points` (NED [m], "
          "shape (n, 2) or (n, 3); a float for one point) and time `t` [s].");
}

}  // namespace kelp_python
