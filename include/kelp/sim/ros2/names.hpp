/// \file
/// \brief ROS 2 names: which strings a topic token and a frame prefix may be (the names of a
/// fleet's vehicles, point masses, anchors and tethers are such names: kelp/sim/ros2/fleet.hpp
/// makes topics and frames of them, timeseries.csv column names). Part of the optional
/// `kelp::sim` component.
#pragma once

#include <string>

namespace kelp {
namespace ros2 {

/// \brief Is `name` usable as a ROS 2 topic token and frame prefix: a letter, then letters,
/// digits and single underscores, not ending with one, at most 64 characters? (The ROS 2 design
/// article "Topic and Service name mapping to DDS": a token holds alphanumerics and
/// underscores, does not start with a digit and has no repeated underscores.)
/// \param name the candidate (ASCII only: any other byte makes it false)
/// \return true when it is such a name
inline bool is_ros_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  const auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  if (!letter(name.front()) || name.back() == '_') return false;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '_' ? name[i - 1] == '_' : !letter(c) && !(c >= '0' && c <= '9')) return false;
  }
  return true;
}

}  // namespace ros2
}  // namespace kelp
