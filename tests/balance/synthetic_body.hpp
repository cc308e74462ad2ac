// A standing humanoid as a BVH clip built in code (CMU or Bandai Namco joint
// names, centimetres, Y up, every rotation zero), its root moved frame by
// frame: the closed-form cases of the ZMP tests.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>

#include "tonus/host/motion/clip.hpp"

namespace tonus::balance::test {

enum class Names { cmu, bandai };

// Hips 95 cm up, legs 42 + 42 cm, ankles 8 cm and toe joints 2 cm above
// y = 0, feet 18 cm apart and pointing +z, arms hanging; 120 Hz. The root's
// displacement from that pose at time t (s, file frame and units) is
// root_offset(t).
[[nodiscard]] motion::Clip synthetic_body(std::size_t frames, Names names,
                                          const std::function<Eigen::Vector3d(double)>& root_offset);

}  // namespace tonus::balance::test
