// The pair's state as archive sections, and the durable file helpers, shared by the state files
// (state_io.cpp) and a run's checkpoint (checkpoint.cpp). Private to the kelp::sim library.
#pragma once

#include <string>

#include "archive.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace sim {
namespace state_sections {

// Writes the pair's state as its sections (HEAD, VEHI, PROP, VEHI, PROP, TETH; docs/
// state-files.md), after the loader's checks (state_error naming `input` when it fails).
void write_pair(archive::Writer& a, const kelp::system::SystemStated& state,
                const std::string& input);
// Reads those sections from the reader's next one, checked on their own and against `model`.
kelp::system::SystemStated read_pair(archive::Reader& r, const kelp::system::SystemModeld& model,
                                     const std::string& input);
// `bytes` as the file `path`: a temporary beside it, fsync, rename, the directory's fsync.
// \throws kelp::error naming the path (the file then unchanged, no temporary left).
void write_file_durably(const std::string& path, const std::string& bytes);
// The whole regular file `path` (at most max_state_file_bytes). \throws kelp::error when it
// cannot be read, state_error when it is not a regular file or too large.
std::string read_whole_file(const std::string& path);

}  // namespace state_sections
}  // namespace sim
}  // namespace kelp
