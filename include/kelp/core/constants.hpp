/// \file
/// \brief Physical constants and the defaults kelp uses when a caller gives none.
#pragma once

namespace kelp {

/// \brief Standard gravity [m/s²] (ISO 80000-3; MoorDyn's default). kelp's default.
inline constexpr double standard_gravity = 9.80665;
/// \brief Seawater density [kg/m³] at ~15 °C, 35 PSU (Fossen 2021, Table 8.1 rounds to 1025).
inline constexpr double seawater_density = 1025.0;
/// \brief Fresh water density [kg/m³].
inline constexpr double freshwater_density = 1000.0;
/// \brief Air density [kg/m³] at 15 °C, sea level (ISA).
inline constexpr double air_density = 1.225;
/// \brief π.
inline constexpr double pi = 3.14159265358979323846;

}  // namespace kelp
