/// \file
/// \brief Where a program finds the replay page's template (kelp/sim/replay.hpp's write_replay()
/// takes its path): `$KELP_REPLAY_TEMPLATE`, the installed copy beside the running program, or
/// the build tree's. Concerns of the process (its environment, /proc/self/exe), not of the
/// library: here, with the programs.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace kelp_apps {

/// \brief Where the replay page's template is: `$KELP_REPLAY_TEMPLATE` when set, else the
/// installed one beside the running program (`<bin>/../share/kelp/replay/replay_template.html`),
/// else `build_tree` (the build's copy, given by the program at compile time); only a path that
/// exists is returned, else "" (three.js was not installed when kelp was built: docs/replay.md).
inline std::string find_replay_template(const std::string& build_tree = {}) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* env = std::getenv("KELP_REPLAY_TEMPLATE"))
    return fs::is_regular_file(env, ec) ? std::string(env) : std::string();
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed =
        self.parent_path().parent_path() / "share/kelp/replay/replay_template.html";
    if (fs::is_regular_file(installed, ec)) return installed.string();
  }
  if (!build_tree.empty() && fs::is_regular_file(build_tree, ec)) return build_tree;
  return {};
}

/// \brief What a program says, once, when find_replay_template() found no template.
inline std::string replay_template_missing_note() {
  const char* env = std::getenv("KELP_REPLAY_TEMPLATE");
  return env ? std::string("the replay template KELP_REPLAY_TEMPLATE=") + env + " does not exist"
             : std::string(
                   "the replay page's template (share/kelp/replay/replay_template.html) is not "
                   "installed: kelp was built without three.js (scripts/install-deps demo "
                   "installs it; see docs/replay.md)");
}

}  // namespace kelp_apps
