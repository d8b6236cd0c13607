// kelp.Batch (issue 27, item 4): filled by its own change. Until then, nothing is bound.
#include "bindings.hpp"

namespace kelp_python {

void bind_batch(py::module_&) {}

}  // namespace kelp_python
