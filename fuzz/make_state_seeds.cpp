// Writes fuzz_state_reader's seeds (fuzz/corpus/fuzz_state_reader/): state files of the fuzz
// target's own systems (state_world.hpp), each after its flags byte, saved by kelp::sim itself:
//
//   cmake --build build/fuzz --target kelp_fuzz_state_seeds &&
//     build/fuzz/kelp_fuzz_state_seeds fuzz/corpus/fuzz_state_reader
#include <cstdio>
#include <string>

#include "kelp/sim/state_io.hpp"
#include "state_world.hpp"

namespace {

namespace ks = kelp::system;

void write(const std::string& dir, const char* name, std::uint8_t flags, const std::string& state) {
  const std::string path = dir + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || std::fputc(flags, f) == EOF ||
      std::fwrite(state.data(), 1, state.size(), f) != state.size() || std::fclose(f) != 0) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::printf("%s: %zu bytes\n", path.c_str(), state.size() + 1);
}

// `bytes` with the u32 at `at` set to `v` (the target reseals the CRC: flag `seal`).
std::string with_u32(std::string bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + std::size_t(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
  return bytes;
}

// The offset of section `index` (0: HEAD) of a state file, at its tag (docs/state-files.md).
std::size_t section_at(const std::string& b, int index) {
  std::size_t at = 13 + static_cast<unsigned char>(b[12]) + 8;
  for (int i = 0; i < index; ++i) {
    std::uint64_t n = 0;
    for (int k = 0; k < 8; ++k)
      n |= std::uint64_t(static_cast<unsigned char>(b[at + 4 + std::size_t(k)])) << (8 * k);
    at += 12 + std::size_t(n);
  }
  return at;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: kelp_fuzz_state_seeds <directory>\n");
    return 2;
  }
  const std::string dir = argv[1];
  using kelp_fuzz::fleet_file, kelp_fuzz::seal, kelp_fuzz::with_model, kelp_fuzz::step_once;
  kelp_fuzz::StateWorld w;
  // The pair at its start, and after its winch inserted a node (history, kept Newton matrix,
  // thrust, a battery that has been loaded).
  ks::SystemStated s = kelp::sim::start_state(w.pair, w.pair_ws, w.world, w.scenario);
  const std::string start = kelp::sim::save_state(s);
  write(dir, "pair_start.bin", seal | with_model | step_once, start);
  ks::SystemInputsd in;
  in.asv_commands.setConstant(w.pair.asv_propulsion()->size(), 0.3);
  in.auv_commands.setConstant(w.pair.auv_propulsion()->size(), 0.2);
  in.winch_payout_rate = 0.5;
  const auto nodes = s.tether.position.cols();
  for (int i = 0; i < 600 && s.tether.position.cols() == nodes; ++i)
    (void)ks::step(w.pair, w.pair_ws, s, in, 0.01);
  for (int i = 0; i < 20; ++i) (void)ks::step(w.pair, w.pair_ws, s, in, 0.01);
  write(dir, "pair_winch.bin", seal | with_model | step_once, kelp::sim::save_state(s));
  write(dir, "pair_winch_unsealed.bin", 0, kelp::sim::save_state(s));
  // Counts just past their bounds, the sections' lengths unchanged: 9 thrusters (8 at most;
  // the section's bytes would hold 10), four billion vehicles.
  write(dir, "pair_nine_thrusters.bin", seal | with_model,
        with_u32(start, section_at(start, 4) + 12, 9));
  write(dir, "pair_many_vehicles.bin", seal,
        with_u32(start, section_at(start, 0) + 12 + 8, 0xFFFFFFFFu));
  // The pair as a fleet, stepped.
  ks::FleetStated f =
      ks::initial_state(w.fleet, w.fleet_ws, {w.world.start.asv, w.world.start.auv}, {});
  ks::FleetInputsd fin(w.fleet);
  fin.winch_payout_rates[0] = -0.3;
  for (int i = 0; i < 50; ++i) (void)ks::step(w.fleet, w.fleet_ws, f, fin, 0.01);
  write(dir, "fleet.bin", fleet_file | seal | with_model | step_once, kelp::sim::save_state(f));
  return 0;
}
