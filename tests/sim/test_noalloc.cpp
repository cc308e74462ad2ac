// The step allocates nothing: every malloc family call and every operator
// new made by our code is counted (operator new replaced here, malloc and
// friends wrapped at link time) over 10,000 steps of the humanoid on the
// ground with objects being thrown at it, added and removed between steps.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

// Debug builds must also run with Eigen's own guard (step() forbids Eigen allocations).
#if !defined(NDEBUG) && !defined(EIGEN_RUNTIME_NO_MALLOC)
#error "debug builds of the physics core must define EIGEN_RUNTIME_NO_MALLOC"
#endif

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

using namespace tonus::sim;

TEST_CASE("10,000 steps with contacts, drives and objects added and removed allocate nothing") {
  const BuildResult built = build_humanoid(HumanoidSpec{});
  REQUIRE(built);
  const Model& model = *built.model;
  auto data = make_data(model);
  StepInputs in = make_inputs(model);
  for (int i = 1; i < model.nbody; ++i) {
    in.kp[static_cast<std::size_t>(i)] *= 100.0;
    in.kd[static_cast<std::size_t>(i)] *= 10.0;
  }
  ObjectSpec ball;
  ball.shape = Shape::sphere(0.05);
  ball.mass_kg = 0.4;
  ball.material.restitution = 0.5;
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.05));

  // Sanity: the counter sees allocations (so zero below means something).
  // (Direct calls, which the compiler may not elide as it may a new-expression.)
  g_counting = true;
  void* volatile probe = ::operator new(16);
  void* volatile raw = std::malloc(16);
  g_counting = false;
  CHECK(g_allocations.load() == 2);
  ::operator delete(probe);
  std::free(raw);
  g_allocations = 0;

  int max_contacts = 0, objects_added = 0, objects_removed = 0;
  g_counting = true;
  ObjectHandle live[3];
  for (int s = 0; s < 10000; ++s) {
    if (s % 500 == 0) {
      // Throw a ball at the chest and drop a cube by the feet; drop the oldest.
      const int slot = (s / 500) % 3;
      if (live[slot].valid()) objects_removed += remove_object(*data, live[slot]) ? 1 : 0;
      ObjectSpec o = slot == 2 ? cube : ball;
      o.pos = slot == 0 ? Vec3(0.8, 0.0, 1.3) : (slot == 1 ? Vec3(0.6, 0.3, 0.3) : Vec3(0.3, -0.2, 0.4));
      o.lin_vel = slot == 0 ? Vec3(-8.0, 0.0, 1.0) : Vec3::Zero();
      live[slot] = add_object(*data, o).handle;
      objects_added += live[slot].valid() ? 1 : 0;
    }
    if (step(model, *data, in) == StepStatus::diverged) break;
    max_contacts = std::max(max_contacts, data->ncon);
  }
  g_counting = false;
  MESSAGE("allocations during 10,000 steps: " << g_allocations.load() << " (peak " << max_contacts << " contacts, "
                                              << objects_added << " objects added, " << objects_removed << " removed)");
  CHECK(g_allocations.load() == 0);
  CHECK(data->status != StepStatus::diverged);
  CHECK(max_contacts > 8);
  CHECK(objects_added == 20);
  CHECK(objects_removed == 17);
}
