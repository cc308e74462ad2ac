// Small synthetic BVH texts and helpers shared by the motion tests.
#pragma once

#include <array>
#include <string>

#include "tonus/host/motion/clip.hpp"

namespace tonus::test {

// Hips (6 channels) -> Chest (3) -> End Site, three frames at 30 Hz, LF
// endings, tab indentation; values are chosen so each column is distinct.
extern const char* const kSmallBvh;

// Path of a clip under the shared data folder's bvh/.
std::string shared_bvh(const std::string& name);

// The names of the seven shared clips.
extern const std::array<const char*, 7> kSharedClips;

// A clip built in code (not read): root "Root" with the six channels in
// `root_channels` order, a child "Arm" with rotation channels only, and an
// End Site, frame_count frames of deterministic pseudo-random values.
motion::Clip synthetic_clip(std::size_t frame_count, unsigned seed);

}  // namespace tonus::test
