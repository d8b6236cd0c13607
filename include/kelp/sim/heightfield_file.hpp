/// \file
/// \brief Height-field seabed files (a bathymetry grid in MoorDyn-C's seafloor format): the file
/// format's reader, part of the compiled kelp::sim (file formats live there; the height field
/// itself, kelp::environment::HeightField, and the contact with it are kelp::kelp's physics).
#pragma once

#include <string>

#include "kelp/environment/obstacles.hpp"
#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {

/// \brief Reads a height field from a bathymetry grid file in MoorDyn-C's seafloor format
/// (MoorDyn v2.7 documentation, docs/inputs.rst, "Seafloor/Bathymetry File"):
/// ```
/// num_x_points num_y_points
/// x_1 x_2 ... x_num_x_points
/// y_1 y_2 ... y_num_y_points
/// x_pos y_pos depth
/// ...
/// ```
/// with x north and y east [m] (kelp's NED) and depth the NED z of the seabed (positive down).
/// kelp asks more than MoorDyn: the x and the y coordinates increasing and evenly spaced (relative
/// spread of the steps ≤ 1e-6), and every grid point given exactly once (MoorDyn leaves a missing
/// or off-grid point undefined); blank lines and lines starting with '#' are skipped.
/// \throws kelp::invalid_argument naming the file and the line for an unreadable file, a
/// missing or malformed number, a count below 2, uneven coordinates, a point off the grid, a
/// point given twice, a missing point or extra text.
/// \param path the file's path. \return the height field (seabed depth z [m], positive down,
/// on a grid in NED x, y [m]).
KELP_SIM_API kelp::environment::HeightField load_heightfield(const std::string& path);

}  // namespace sim
}  // namespace kelp
