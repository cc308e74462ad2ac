// Shared helpers for the balance tests: loading a clip through the whole
// conversion (the clips' paths are in clip_paths.hpp).
#pragma once

#include <string>

#include "clip_paths.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace tonus::balance::test {

struct Loaded {
  motion::Clip clip;
  MapResult mapping;
  Conversion conversion;
};

// Reads, maps and converts a clip; fails the test on any error.
Loaded load(const std::string& path, const ConvertOptions& options = {});

}  // namespace tonus::balance::test
