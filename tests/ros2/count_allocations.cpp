// Global operator new replaced to count heap allocations (the MCAP writer's steady state must
// make none). Compiled on its own, outside the unity build, so that no caller sees the
// definitions.
#include <cstdlib>
#include <new>

namespace kelp_test {
long allocations = 0;
}

void* operator new(std::size_t n) {
  ++kelp_test::allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
