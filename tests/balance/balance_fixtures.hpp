// Shared helpers for the balance tests: loading a clip through the whole
// conversion (the clips' paths are in clip_paths.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

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

// Euler discontinuities: per column of a frame row, how many consecutive
// frames differ by more than `degrees` (rotation channels; position columns
// count zero). With `lock_margin_deg`, a pair of frames either of which has
// its joint's middle angle within that of +-90 degrees is not counted: a
// rotation passing that close to gimbal lock turns the first and last angles
// by up to 180 degrees within a few frames in any Euler representation.
std::vector<std::size_t> rotation_jumps(const motion::Clip& clip, double degrees = 90.0, double lock_margin_deg = 0.0);
// The motion with its leading T-pose (the frames before first_frame) cut off.
HumanMotion without_leading_tpose(const HumanMotion& m);
// "Joint Channel" for a column of a frame row, for messages.
std::string column_name(const motion::Clip& clip, std::size_t column);

}  // namespace tonus::balance::test
