// The learning environment's C++ part (issue 27, item 5), if it needs one. Until then, nothing
// is bound.
#include "bindings.hpp"

namespace kelp_python {

void bind_learning(py::module_&) {}

}  // namespace kelp_python
