// A VMC performer's bundles regrouped into the sender's frames (SenderFrames):
// split frames, several frames in one call, a skeleton not known yet.
#include <doctest/doctest.h>

#include <vector>

#include "tonus/host/daemon/sender_frames.hpp"

using namespace tonus;
using daemon::SenderFrame;
using daemon::SenderFrames;

namespace {

constexpr std::size_t kN = sim::kBoneCount;

// The bones [from, to) of frame `k` (each bone's quaternion carries k), and the root with the first part.
reference::BodySample part(int k, std::size_t from, std::size_t to) {
  reference::BodySample s;
  for (std::size_t b = from; b < to; ++b) {
    s.present[b] = true;
    s.local[b] = sim::Quat(Eigen::AngleAxisd(0.01 * k, sim::Vec3::UnitX()));
  }
  if (from == 0) {
    s.root_present = true;
    s.root_position = sim::Vec3(0.01 * k, 0.0, 1.0);
  }
  return s;
}

}  // namespace

TEST_CASE("sender frames: a frame split over bundles is one frame, however the bundles are grouped") {
  std::array<bool, kN> skeleton{};
  skeleton.fill(true);
  SenderFrames framer;
  std::vector<SenderFrame> done;
  // Frame 1 in two bundles: complete once both have come.
  framer.add(part(1, 0, 10), 100, &skeleton, done);
  CHECK(done.empty());
  framer.add(part(1, 10, kN), 110, &skeleton, done);
  REQUIRE(done.size() == 1);
  CHECK(done[0].arrival_us == 110);
  CHECK(done[0].body.root_position.x() == doctest::Approx(0.01));
  // Frames 2 and 3 back to back, then half of 4.
  for (int k = 2; k <= 3; ++k) {
    framer.add(part(k, 0, 10), 100 * k, &skeleton, done);
    framer.add(part(k, 10, kN), 100 * k + 5, &skeleton, done);
  }
  framer.add(part(4, 0, 10), 400, &skeleton, done);
  REQUIRE(done.size() == 3);
  CHECK(done[2].body.root_position.x() == doctest::Approx(0.03));
  CHECK(done[2].body.local[kN - 1].isApprox(sim::Quat(Eigen::AngleAxisd(0.03, sim::Vec3::UnitX()))));
}

TEST_CASE("sender frames: without a skeleton, or with bones the sender leaves out, a repeated bone ends the frame") {
  SenderFrames framer;
  std::vector<SenderFrame> done;
  for (int k = 1; k <= 3; ++k) {
    framer.add(part(k, 0, 5), 10 * k, nullptr, done);
    framer.add(part(k, 5, 12), 10 * k + 1, nullptr, done);  // bones 12.. never come
  }
  REQUIRE(done.size() == 2);  // the third is still open: its end is the next frame's start
  for (const SenderFrame& f : done) {
    CHECK(f.body.present[11]);
    CHECK_FALSE(f.body.present[12]);
  }
  CHECK(done[1].arrival_us == 21);
  std::array<bool, kN> skeleton{};
  skeleton.fill(true);  // the sender's skeleton has them all, but the sender leaves some out
  framer.add(part(4, 0, 12), 40, &skeleton, done);
  REQUIRE(done.size() == 3);  // frame 3 ended by frame 4's repeated bones
  CHECK(done[2].body.root_position.x() == doctest::Approx(0.03));
}
