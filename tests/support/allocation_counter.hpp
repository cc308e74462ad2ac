// Counts heap allocations made while counting is on: every operator new
// (replaced in allocation_counter.cpp) and every malloc, calloc, realloc,
// posix_memalign and aligned_alloc called from the test binary's own objects
// (wrapped at link time by the tonus_allocation_counter CMake target).
#pragma once

namespace tonus::test {

void start_counting_allocations();
// Stops and returns how many allocations happened since the last start.
long stop_counting_allocations();

// Makes two allocations while counting (a malloc and an operator new) and
// returns what the counter saw: 2 when it works, so a zero elsewhere means something.
long probe_allocation_counter();

}  // namespace tonus::test
