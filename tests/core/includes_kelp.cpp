// A translation unit that includes kelp, compiled by refuse_fast_math.cmake with and without
// floating-point flags kelp refuses (kelp/core/compiler_checks.hpp).
#include "kelp/environment/waves.hpp"
#include "kelp/kelp.hpp"

int main() { return 0; }
