// Height-field seabed files (kelp::sim::load_heightfield, kelp/sim/heightfield_file.hpp): MoorDyn's
// seafloor format read into kelp's grid, and every malformed file refused with a message naming
// the file and the line.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "kelp/environment/obstacles.hpp"
#include "kelp/sim/heightfield_file.hpp"

namespace ke = kelp::environment;
namespace ks = kelp::sim;

namespace {

// The height-field files, in a directory of their own under the system's temporary directory
// (removed when the test process ends), not in the working directory.
const std::filesystem::path& scratch_dir() {
  static const struct Dir {
    std::filesystem::path path;
    Dir()
        : path(std::filesystem::temp_directory_path() /
               ("kelp_test_heightfield_" + std::to_string(std::random_device{}()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = (scratch_dir() / (name + ".txt")).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("height-field file: MoorDyn's seafloor format and clear errors", "[obstacles]") {
  const std::string good = write_file("hf_good",
                                      "# comment\n3 2\n0 5 10\n-2 2\n"
                                      "0 -2 30\n0 2 31\n5 -2 32\n5 2 33\n10 -2 34\n10 2 35\n");
  const ke::HeightField hf = ks::load_heightfield(good);
  CHECK(hf.rows == 3);
  CHECK(hf.cols == 2);
  CHECK(hf.spacing.x() == Approx(5));
  CHECK(hf.spacing.y() == Approx(4));
  CHECK(hf.at(2, 1) == Approx(35));
  CHECK(hf.at(1, 0) == Approx(32));
  CHECK(ke::sample_heightfield<double>(hf, 7.5, 0.0).depth == Approx(0.5 * (32.5 + 34.5)));
  const auto fails = [](const std::string& name, const std::string& text, const char* what) {
    const std::string path = write_file(name, text);
    CHECK_THROWS_AS(ks::load_heightfield(path), kelp::invalid_argument);
    CHECK_THROWS_WITH(ks::load_heightfield(path), Catch::Matchers::Contains(what));
  };
  CHECK_THROWS_AS(ks::load_heightfield("no/such/file.txt"), kelp::invalid_argument);
  CHECK_THROWS_WITH(ks::load_heightfield("no/such/file.txt"),
                    Catch::Matchers::Contains("cannot open"));
  fails("hf_count", "1 2\n0\n0 1\n0 0 1\n0 1 1\n", "whole numbers in [2");
  fails("hf_nan", "2 2\n0 1\n0 1\n0 0 1\n0 1 nan\n1 0 1\n1 1 1\n", "not a finite number");
  fails("hf_uneven", "3 2\n0 1 3\n0 1\n", "evenly spaced");
  fails("hf_decreasing", "2 2\n1 0\n0 1\n", "must increase");
  fails("hf_missing", "2 2\n0 1\n0 1\n0 0 1\n0 1 1\n1 0 1\n", "expected 4 lines");
  fails("hf_twice", "2 2\n0 1\n0 1\n0 0 1\n0 0 1\n1 0 1\n1 1 1\n", "given twice");
  fails("hf_offgrid", "2 2\n0 1\n0 1\n0 0 1\n0 0.5 1\n1 0 1\n1 1 1\n", "not on the grid");
  fails("hf_short", "2 2\n0 1\n0 1\n0 0 1\n0 1\n1 0 1\n1 1 1\n", "line 5");
}
