// The non-finite values the bad-input tests feed kelp. One definition for every test file of a
// directory's executable (tests/CMakeLists.txt compiles them as one unit).
#pragma once

#include <limits>

namespace kelp_test {

inline constexpr double kNan = std::numeric_limits<double>::quiet_NaN();  ///< a quiet NaN
inline constexpr double kInf = std::numeric_limits<double>::infinity();   ///< +∞

}  // namespace kelp_test
