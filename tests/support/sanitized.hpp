// The sanitizer build (CMakePresets.json "asan") runs every test that can
// find a memory or undefined-behaviour fault, but not the long figure checks
// whose code the shorter tests already walk: each of those takes 1-2 minutes
// under ASan and finds nothing the short ones do not. They run in full in the
// release build. Mark one with `* tonus::test::heavy_under_sanitizers()`: a
// skipped doctest case is not even listed, so ctest never registers it there.
// Randomised sweeps instead run a share of their cases (sanitized_cases).
#pragma once

#include <doctest/doctest.h>

namespace tonus::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

inline doctest::skip heavy_under_sanitizers() { return doctest::skip(kSanitized); }

// n cases in the release build, a fifth of them under sanitizers.
constexpr int sanitized_cases(int n) { return kSanitized ? n / 5 : n; }

}  // namespace tonus::test
