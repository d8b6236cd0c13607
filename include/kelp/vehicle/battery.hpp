/// \file
/// \brief A battery pack: open-circuit voltage as a tabulated function of the state of charge,
/// a series internal resistance, and counters of the charge and energy drawn. Terminal voltage
/// V = OCV(SoC) − R I (a Rint equivalent circuit: no RC branches, so no relaxation after a load
/// step; the sag under load is immediate).
///
/// The battery works in double precision for every model Scalar, as the clock does (DESIGN's "one
/// clock" rule): its counters sum small increments over hours (0.2 C per 10 ms step at 20 A
/// into ~56 000 C), which float cannot hold.
///
/// Presets (battery_presets):
/// - `bluerov2_battery()`: the Blue Robotics Lithium-ion Battery 14.8 V 15.6 Ah, part BR-100839
///   (Blue Robotics Lithium-ion Battery Guide, bluerobotics.com/learn/battery-info: 4S, nominal
///   14.8 V = 3.7 V per cell, maximum 16.8 V = 4.2 V per cell, minimum 12.0 V = 3.0 V per cell).
///   It is sometimes called a LiPo; the product is a Li-ion pack of cylindrical cells charged with
///   LiPo settings, and kelp models it as Li-ion.
/// - `blueboat_battery()`: two of those packs in parallel (31.2 Ah, 20 mΩ).
#pragma once

#include <cmath>
#include <limits>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"

namespace kelp::vehicle {

/// \brief An open-circuit-voltage curve of one cell: `size` points (SoC ∈ [0, 1] ascending, from
/// 0 to 1, and the cell's OCV [V] there), linear in between.
struct OcvCurve {
  /// Most points a curve holds.
  static constexpr int max_points = 32;
  int size = 0;                          ///< points used
  double soc[max_points] = {};           ///< state of charge, 0 … 1, strictly ascending
  double cell_voltage[max_points] = {};  ///< OCV of one cell [V], non-decreasing
};

/// \brief Li-ion (NMC, 18650) cell OCV(SoC), sampled from the curve measured on a Sony/Murata
/// US18650VTC6 cell (charged to 4.2 V, rested 24 h, discharged at C/20 to 2.5 V and charged back
/// at C/20; the two curves averaged: D. Lucae, "US18650VTC6_OCV_SOC_Curve", GitHub
/// derlucae98/US18650VTC6_OCV_SOC_Curve, lookup table US18650VTC6_OCV_SOC_LUT.h), linearly
/// interpolated at 0, 1, 2.5, 5, 10, 15 … 95, 100 % (its first point, 2.535 V at 0.2 %, is used
/// for 0 %). Blue Robotics does not publish its packs' OCV curve nor their cells; any
/// NMC/graphite cell has this shape within a few tens of mV. On this curve the pack's 3.0 V/cell
/// minimum (Blue Robotics) is reached at 2.8 % SoC: the rated capacity is taken over the whole
/// table (the ~3 % difference is within the spread between cells).
inline constexpr OcvCurve li_ion_nmc_ocv{
    23,
    {0.0,  0.01, 0.025, 0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45,
     0.50, 0.55, 0.60,  0.65, 0.70, 0.75, 0.80, 0.85, 0.90, 0.95, 1.0},
    {2.535, 2.760, 2.972, 3.133, 3.268, 3.350, 3.413, 3.499, 3.559, 3.610, 3.661, 3.706,
     3.753, 3.798, 3.839, 3.882, 3.923, 3.979, 4.037, 4.075, 4.091, 4.113, 4.175}};

/// \brief A battery pack (double precision for every model Scalar: see the file comment).
struct BatteryParameters {
  /// Rated capacity [Ah] (the charge from SoC 1 to SoC 0).
  double capacity_ah = 15.6;
  /// Cells in series (the pack's OCV is this times the cell's).
  int cells_in_series = 4;
  /// Series resistance of the pack, cells, wiring and connectors [Ω].
  double internal_resistance = 0.04;
  /// State of charge at the start of a run, in [0, 1].
  double initial_soc = 1.0;
  /// Constant current of everything but the thrusters (electronics, lights) [A], ≥ 0.
  double hotel_current = 0.0;
  /// OCV(SoC) of one cell.
  OcvCurve ocv = li_ion_nmc_ocv;
};

/// \brief Throws kelp::invalid_argument naming the field unless the capacity and the cell count
/// are positive, the resistance and the hotel current non-negative, the initial SoC in [0, 1]
/// and the OCV curve has 2 … max_points points, SoC ascending from 0 to 1, finite positive
/// non-decreasing voltages.
/// \param p the battery's parameters.
inline void validate(const BatteryParameters& p) {
  check_positive(p.capacity_ah, "battery.capacity_ah");
  KELP_CHECK(p.cells_in_series >= 1 && p.cells_in_series <= 1000,
             "battery.cells_in_series must be in [1, 1000]");
  check_non_negative(p.internal_resistance, "battery.internal_resistance");
  check_non_negative(p.hotel_current, "battery.hotel_current");
  KELP_CHECK(std::isfinite(p.initial_soc) && p.initial_soc >= 0.0 && p.initial_soc <= 1.0,
             "battery.initial_soc must be in [0, 1]");
  const OcvCurve& c = p.ocv;
  KELP_CHECK(c.size >= 2 && c.size <= OcvCurve::max_points, "battery.ocv must have 2 to 32 points");
  KELP_CHECK(c.soc[0] == 0.0, "battery.ocv must start at SoC 0");
  for (int i = 0; i < c.size; ++i) {
    check_positive(c.cell_voltage[i], "battery.ocv cell voltage");
    if (i > 0) {
      KELP_CHECK(c.soc[i] > c.soc[i - 1] && c.soc[i] <= 1.0,
                 "battery.ocv SoC must be ascending in [0, 1]");
      KELP_CHECK(c.cell_voltage[i] >= c.cell_voltage[i - 1],
                 "battery.ocv voltage must not decrease with SoC");
    }
  }
  KELP_CHECK(c.soc[c.size - 1] == 1.0, "battery.ocv must end at SoC 1");
}

/// \brief What a battery has delivered since the start of the run, and its last load.
struct BatteryState {
  double charge_drawn = 0.0;  ///< ∫ I dt [C]
  double energy_drawn = 0.0;  ///< ∫ V I dt [J] (at the terminals)
  /// Terminal voltage over the last step [V] (NaN before the first: not yet loaded).
  double voltage = std::numeric_limits<double>::quiet_NaN();
  double current = 0.0;  ///< current over the last step [A] (thrusters + hotel load)
};

/// \brief State of charge [−] of `s`: initial_soc − charge_drawn / (3600 capacity_ah). Below 0
/// when the pack has been drawn past its rated capacity (OCV then stays at its SoC-0 value).
/// \param p the battery. \param s what it has delivered. \return the SoC, 1 full, 0 empty.
inline double state_of_charge(const BatteryParameters& p, const BatteryState& s) {
  return p.initial_soc - s.charge_drawn / (3600.0 * p.capacity_ah);
}

/// \brief The pack's open-circuit voltage [V] at state of charge `soc` (clamped to [0, 1]):
/// cells_in_series × the cell curve, linear between its points.
/// \param p the battery. \param soc state of charge [−]. \return the OCV [V].
inline double open_circuit_voltage(const BatteryParameters& p, double soc) {
  const OcvCurve& c = p.ocv;
  const double x = soc < 0.0 ? 0.0 : (soc > 1.0 ? 1.0 : soc);
  int i = 1;
  while (i < c.size - 1 && c.soc[i] < x) ++i;
  const double w = c.soc[i] - c.soc[i - 1];
  const double f = (x - c.soc[i - 1]) / w;  // w > 0: validate() asks for ascending SoC
  return p.cells_in_series *
         (c.cell_voltage[i - 1] + f * (c.cell_voltage[i] - c.cell_voltage[i - 1]));
}

/// \brief Terminal voltage [V] under a current `current` [A] (discharge positive):
/// OCV(SoC) − R I.
/// \param p the battery. \param s its state (the SoC). \param current the load [A].
/// \return the terminal voltage [V] (negative only for absurd currents; not clamped).
inline double terminal_voltage(const BatteryParameters& p, const BatteryState& s, double current) {
  return open_circuit_voltage(p, state_of_charge(p, s)) - p.internal_resistance * current;
}

/// \brief The terminal voltage of a load whose current depends on the voltage: the root of
/// g(V) = V − OCV + R (I_load(V) + I_hotel) on [0, OCV] (g is increasing when the load draws more
/// at a higher voltage, as a thruster at a fixed command does; g(OCV) ≥ 0), to |g| < 1e-9 V.
/// From `guess` (e.g. the previous step's voltage; NaN or outside (0, OCV]: the OCV), one
/// fixed-point step V₁ = OCV − R I(V₀) and secant steps, 2–4 load evaluations a call when the
/// load changes little between calls; a secant step that leaves [0, OCV] or 8 that do not
/// converge hand over to Illinois' false position on the bracket [0, OCV]. With the BlueROV2's
/// eight thrusters at full command the loop gain R dI/dV is ≈ 0.5–0.8, so taking the previous
/// step's voltage instead (an explicit lag of one step) would ring from step to step; this solves
/// the coupling within the step. The returned voltage is always the point of the last load
/// evaluation (a caller may keep what its load computed there).
/// \tparam Load a callable `double(double V)`.
/// \param[in] p the battery. \param[in] s its state (the SoC, hence the OCV).
/// \param[in] load `double(double V)`, the load's current [A] at terminal voltage V (≥ 0).
/// \param[in] guess a starting voltage [V] (NaN: start from the OCV).
/// \returns V [V]; 0 when even at 0 V the load pulls the pack below 0.
/// \throws kelp::numerical_error when the load returns a non-finite or negative current.
template <typename Load>
double solve_terminal_voltage(const BatteryParameters& p, const BatteryState& s, Load&& load,
                              double guess = std::numeric_limits<double>::quiet_NaN()) {
  const double ocv = open_circuit_voltage(p, state_of_charge(p, s));
  const double r = p.internal_resistance;
  const auto g = [&](double v) {
    const double i = load(v);
    if (!(i >= 0.0) || !std::isfinite(i))
      ::kelp::detail::throw_numerical_error(
          "battery: the load's current is negative or not finite");
    return v - ocv + r * (i + p.hotel_current);
  };
  constexpr double tol = 1e-9;
  if (r == 0.0) {
    (void)g(ocv);
    return ocv;
  }
  // Warm start: secant iterations.
  double v0 = std::isfinite(guess) && guess > 0.0 && guess <= ocv ? guess : ocv;
  double g0 = g(v0);
  if (std::abs(g0) < tol) return v0;
  double v1 = v0 - g0;  // the fixed-point step OCV − R I(V₀)
  for (int k = 0; k < 8 && v1 >= 0.0 && v1 <= ocv; ++k) {
    const double g1 = g(v1);
    if (std::abs(g1) < tol) return v1;
    if (g1 == g0) break;
    const double v2 = v1 - g1 * (v1 - v0) / (g1 - g0);
    v0 = v1;
    g0 = g1;
    v1 = v2;
  }
  // Safeguarded: Illinois on [0, OCV].
  double a = 0.0, b = ocv;
  double ga = g(a);
  if (ga >= 0.0) return 0.0;
  double gb = g(b);
  if (gb <= tol) return ocv;
  int side = 0;
  double v = b;
  for (int k = 0; k < 100; ++k) {
    v = (a * gb - b * ga) / (gb - ga);
    if (!(v > a && v < b)) v = 0.5 * (a + b);
    const double gv = g(v);
    if (std::abs(gv) < tol || b - a < tol) break;
    if (gv < 0.0) {
      a = v;
      ga = gv;
      if (side == -1) gb *= 0.5;
      side = -1;
    } else {
      b = v;
      gb = gv;
      if (side == 1) ga *= 0.5;
      side = 1;
    }
  }
  return v;
}

/// \brief Draws `current` [A] at terminal voltage `voltage` [V] for `dt` [s]: the counters grow by
/// I dt and V I dt (exact for a load held over the step); the state records V and I.
/// \param s the battery's state, updated. \param current the load [A] (discharge positive).
/// \param voltage the terminal voltage [V]. \param dt the step [s].
inline void drain(BatteryState& s, double current, double voltage, double dt) {
  s.charge_drawn += current * dt;
  s.energy_drawn += voltage * current * dt;
  s.current = current;
  s.voltage = voltage;
}

namespace battery_presets {

/// \brief Blue Robotics Lithium-ion Battery 14.8 V 15.6 Ah (BR-100839; see the file comment):
/// 4S, 15.6 Ah, the Li-ion cell curve li_ion_nmc_ocv (16.7 V full, 14.9 V at 50 % SoC).
/// Internal resistance 40 mΩ: assumed (Blue Robotics publishes none; energy-type 18650/21700
/// cells have ~20–30 mΩ DC resistance, a 4S pack of parallel groups ≈ 20–30 mΩ, plus ~10 mΩ of
/// wiring, connectors and the power sense module). No hotel load (set `hotel_current` for the
/// electronics and lights).
/// \return the pack's parameters.
inline BatteryParameters bluerov2_battery() { return BatteryParameters{}; }

/// \brief The BlueBoat's pack: two bluerov2_battery() packs in parallel (31.2 Ah, 20 mΩ).
/// Assumed from Blue Robotics' BlueBoat, which carries two of its 14.8 V Li-ion batteries wired
/// in parallel (the product page was not available to check; the capacity scales linearly with
/// the packs' number, their resistance inversely).
/// \return the pack's parameters.
inline BatteryParameters blueboat_battery() {
  BatteryParameters p;
  p.capacity_ah = 2 * 15.6;
  p.internal_resistance = 0.5 * 0.04;
  return p;
}

}  // namespace battery_presets

}  // namespace kelp::vehicle
