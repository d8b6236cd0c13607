// kelp_scenario_reference: docs/scenario-reference.md, generated from the scenario parser's table
// (src/scenario.cpp's scenario_fields, through scenario_reference_markdown()), and its checks.
//
//   kelp_scenario_reference write FILE               writes the reference to FILE
//   kelp_scenario_reference check FILE [DOC...] [-- SCENARIO...]
//       fails unless FILE is what `write` would write (the reference is stale: run the target
//       scenario_reference_update); then parses every ```json block of FILE and of each DOC
//       (README.md, docs/scenarios.md) and every SCENARIO file with kelp::sim::parse_scenario, and
//       fails on the first that does not parse.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kelp/sim/scenario.hpp"
#include "scenario_reference.hpp"

namespace {

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The ```json blocks of a Markdown text.
std::vector<std::string> json_blocks(const std::string& text) {
  std::vector<std::string> blocks;
  std::size_t at = 0;
  const std::string open = "```json\n";
  while ((at = text.find(open, at)) != std::string::npos) {
    const std::size_t start = at + open.size();
    const std::size_t end = text.find("\n```", start);
    if (end == std::string::npos) break;
    blocks.push_back(text.substr(start, end - start));
    at = end + 4;
  }
  return blocks;
}

}  // namespace

int main(int argc, char** argv) {
  namespace sim = kelp::sim;
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    const std::string reference = sim::detail::scenario_reference_markdown();
    if (args.size() == 2 && args[0] == "write") {
      std::ofstream out(args[1], std::ios::binary);
      out << reference;
      if (!out.flush()) throw std::runtime_error(args[1] + ": cannot be written");
      std::printf("scenario_reference: wrote %s\n", args[1].c_str());
      return 0;
    }
    if (args.size() < 2 || args[0] != "check") {
      std::fprintf(stderr,
                   "usage: kelp_scenario_reference write FILE | check FILE [DOC...] "
                   "[-- SCENARIO...]\n");
      return 2;
    }
    if (read(args[1]) != reference) {
      std::fprintf(stderr,
                   "scenario_reference: %s is not what the parser's table gives; regenerate it "
                   "(cmake --build <build> --target scenario_reference_update)\n",
                   args[1].c_str());
      return 1;
    }
    int examples = 0, files = 0;
    bool scenarios = false;
    for (std::size_t i = 1; i < args.size(); ++i) {
      if (args[i] == "--") {
        scenarios = true;
        continue;
      }
      if (scenarios) {
        sim::load_scenario(args[i]);
        ++files;
        continue;
      }
      int n = 0;
      for (const std::string& block : json_blocks(read(args[i]))) {
        sim::parse_scenario(block, args[i] + " (example " + std::to_string(++n) + ")");
        ++examples;
      }
      if (i == 1 && n == 0) throw std::runtime_error(args[1] + ": no ```json example");
    }
    std::printf("scenario_reference: up to date; %d examples and %d scenario files parse\n",
                examples, files);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scenario_reference: %s\n", e.what());
    return 1;
  }
}
