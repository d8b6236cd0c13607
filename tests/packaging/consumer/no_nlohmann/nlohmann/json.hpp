// Stands in for nlohmann-json's header in front of the system's: kelp::sim's installed headers
// must not include it (nlohmann-json is private to the compiled library), so any that does fails
// to compile here.
#error "a kelp::sim header includes <nlohmann/json.hpp>: its consumers must not need nlohmann-json"
