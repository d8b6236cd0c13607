// Counts the heap allocations of the whole program, wherever they are compiled: the test's own
// code, the compiled kelp::sim library, Eigen's allocator (which calls malloc, not operator new)
// and the C++ library. Include it in exactly ONE translation unit of a program (it defines the
// allocation functions), then compare kelp_test::heap_allocations() before and after the code
// that must not allocate.
//
// With glibc the malloc family itself is interposed (the program's malloc, calloc, realloc,
// memalign, posix_memalign and aligned_alloc count and forward to glibc's __libc_* functions;
// operator new and Eigen allocate through them). Under AddressSanitizer, whose own malloc must
// not be replaced, operator new is counted instead (Eigen's own allocations are then left to
// EIGEN_RUNTIME_NO_MALLOC in the units compiled with it).
#pragma once

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>
#if defined(__GLIBC__) || defined(__linux__)
#include <malloc.h>  // memalign
#endif
#if defined(__clang__) && (defined(__x86_64__) || defined(__i386__))
// Clang's <mm_malloc.h> (included by Eigen through the SSE headers) declares posix_memalign
// without noexcept; declared after the definition below, that is an error, declared before it
// is taken as the same function.
#include <mm_malloc.h>
#endif

namespace kelp_test {
inline std::atomic<long> g_heap_allocations{0};
/// Heap allocations of the program so far.
inline long heap_allocations() { return g_heap_allocations.load(std::memory_order_relaxed); }
}  // namespace kelp_test

#if defined(__SANITIZE_ADDRESS__)
#define KELP_TEST_HEAP_COUNTER_NEW 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define KELP_TEST_HEAP_COUNTER_NEW 1
#endif
#endif

#if !defined(KELP_TEST_HEAP_COUNTER_NEW) && defined(__GLIBC__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(alignment, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) noexcept { __libc_free(p); }
}
#else
// Every operator new of the program is counted: the non-array, non-aligned forms are replaced,
// new and delete together, on std::malloc/std::free (libstdc++'s default operator new[] calls
// the replaced operator new, its delete[] the replaced delete).
void* operator new(std::size_t n) {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  kelp_test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push  // GCC takes the inlined malloc/free pair for a new/free mismatch
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif
