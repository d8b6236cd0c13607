/// \file
/// \brief Umbrella header: everything in kelp that needs Eigen only (not `kelp/ceres/`).
#pragma once

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/state.hpp"
