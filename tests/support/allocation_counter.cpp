#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
void count() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// The linker's --wrap names are reserved identifiers by construction.
// NOLINTBEGIN(bugprone-reserved-identifier)
extern "C" {
void* __real_malloc(std::size_t n);
void* __real_calloc(std::size_t n, std::size_t s);
void* __real_realloc(void* p, std::size_t n);
int __real_posix_memalign(void** p, std::size_t a, std::size_t n);
void* __real_aligned_alloc(std::size_t a, std::size_t n);
void* __wrap_malloc(std::size_t n) {
  count();
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t s) {
  count();
  return __real_calloc(n, s);
}
void* __wrap_realloc(void* p, std::size_t n) {
  count();
  return __real_realloc(p, n);
}
int __wrap_posix_memalign(void** p, std::size_t a, std::size_t n) {
  count();
  return __real_posix_memalign(p, a, n);
}
void* __wrap_aligned_alloc(std::size_t a, std::size_t n) {
  count();
  return __real_aligned_alloc(a, n);
}
}
// NOLINTEND(bugprone-reserved-identifier)

void* operator new(std::size_t n) {
  count();
  if (void* p = __real_malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace tonus::test {

void start_counting_allocations() {
  g_allocations = 0;
  g_counting = true;
}

long stop_counting_allocations() {
  g_counting = false;
  return g_allocations.load();
}

long probe_allocation_counter() {
  start_counting_allocations();
  // Direct calls through volatile pointers: a new-expression may be elided, these may not.
  void* volatile raw = std::malloc(16);
  void* volatile object = ::operator new(16);
  const long seen = stop_counting_allocations();
  std::free(raw);
  ::operator delete(object);
  return seen;
}

}  // namespace tonus::test
