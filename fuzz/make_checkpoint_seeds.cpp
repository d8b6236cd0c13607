// Writes fuzz_checkpoint_reader's seeds (fuzz/corpus/fuzz_checkpoint_reader/): checkpoints of the
// target's own loops (the fuzz worlds' pair with its winch, with and without navigation from
// sensors), each after its flags byte, written by kelp::sim itself:
//
//   cmake --build build/fuzz --target kelp_fuzz_checkpoint_seeds &&
//     build/fuzz/kelp_fuzz_checkpoint_seeds fuzz/corpus/fuzz_checkpoint_reader
#include <cstdio>
#include <cstdlib>
#include <string>

#include "checkpoint.hpp"
#include "state_world.hpp"

namespace {

namespace sim = kelp::sim;

void write(const std::string& dir, const char* name, std::uint8_t flags, const std::string& bytes) {
  const std::string path = dir + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || std::fputc(flags, f) == EOF ||
      std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::printf("%s: %zu bytes\n", path.c_str(), bytes.size() + 1);
}

// The fuzz target's loop (fuzz_checkpoint_reader.cpp's World), stepped `steps` times.
std::string checkpoint_of(bool sensors, int steps) {
  sim::Scenario sc = kelp_fuzz::StateWorld::make_scenario();
  sc.duration = 2.0;
  if (sensors) sc.navigation.mode = sim::NavigationMode::sensors;
  const sim::WorldSetup world = sim::world_setup(sc, "fuzz_checkpoint");
  sim::ClosedLoop loop(sc, world);
  for (int i = 0; i < steps; ++i) loop.step();
  return sim::checkpoint_bytes(loop);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: kelp_fuzz_checkpoint_seeds <directory>\n");
    return 2;
  }
  const std::string dir = argv[1];
  // Flags (fuzz_checkpoint_reader.cpp): 1 sensors, 2 seal, 4 step.
  write(dir, "start.bin", 2 | 4, checkpoint_of(false, 0));
  write(dir, "stepped.bin", 2 | 4, checkpoint_of(false, 120));
  write(dir, "stepped_unsealed.bin", 0, checkpoint_of(false, 120));
  write(dir, "sensors.bin", 1 | 2 | 4, checkpoint_of(true, 120));
  return 0;
}
