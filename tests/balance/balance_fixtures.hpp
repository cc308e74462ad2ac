// Shared helpers for the balance tests: loading a clip through the whole
// conversion, and the shared mocap clips' paths.
#pragma once

#include <string>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace tonus::balance::test {

inline std::string shared_clip(const std::string& name) { return std::string(TONUS_SHARED_DATA_DIR) + "/bvh/" + name; }
inline std::string bundled_clip(const std::string& name) {
  return std::string(TONUS_SOURCE_DIR) + "/tests/data/" + name;
}

struct Loaded {
  motion::Clip clip;
  MapResult mapping;
  Conversion conversion;
};

// Reads, maps and converts a clip; fails the test on any error.
Loaded load(const std::string& path, const ConvertOptions& options = {});

}  // namespace tonus::balance::test
