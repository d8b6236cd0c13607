// The SDF importer when kelp::sim was built without tinyxml2 (kelp/sim/vehicle_file.hpp): it
// says so instead of importing.
#include "kelp/sim/vehicle_file.hpp"

namespace kelp {
namespace sim {

SdfImport parse_sdf(const std::string&, const std::string& file, const SdfImportOptions&) {
  throw error(file +
              ": kelp::sim was built without tinyxml2, so it cannot import SDF "
              "(install libtinyxml2-dev and build kelp again)");
}

SdfImport import_sdf(const std::string& path, const SdfImportOptions& options) {
  return parse_sdf("", path, options);
}

}  // namespace sim
}  // namespace kelp
