// Real clips retargeted onto the humanoid: its own forward kinematics must
// point every limb segment where the clip's landmarks do, stand the feet on
// z = 0 where the clip's feet are down, keep every joint in range and every
// quaternion unit and continuous.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "reference_checks.hpp"

using namespace tonus::reference;

namespace {

void check_clip(const std::string& name, const std::string& path) {
  const tonus::balance::Conversion conv = test::load(path);
  const ClipReference ref = clip_to_reference(test::humanoid(), conv.motion);
  REQUIRE_MESSAGE(ref.ok(), ref.error);
  REQUIRE(ref.qpos.size() == conv.motion.size());
  CHECK(ref.nq == test::humanoid().nq);
  const test::Figures fig = test::evaluate(test::humanoid(), conv.motion, ref);
  std::string seg;
  for (std::size_t k = 0; k < test::kSegmentKinds; ++k) {
    const test::Spread& s = fig.segment_deg[k];
    seg += std::string("\n  ") + test::kSegmentNames[k] + ": median " + std::to_string(s.median) + ", p95 " +
           std::to_string(s.p95) + ", max " + std::to_string(s.max) + " deg (" + std::to_string(s.n) + ")";
  }
  std::string notes;
  for (const std::string& m : ref.messages) notes += "\n  " + m;
  MESSAGE(name << ": direction agreement, all segments: median " << fig.all_deg.median << ", p95 " << fig.all_deg.p95
               << ", max " << fig.all_deg.max << " deg" << seg << "\n  feet in contact |z|: median "
               << fig.contact_foot_z_m.median << ", p95 " << fig.contact_foot_z_m.p95 << ", max "
               << fig.contact_foot_z_m.max << " m (" << fig.contact_foot_z_m.n << ")\n  largest joint step "
               << fig.max_step_deg << " deg; frames clamped " << ref.frames_clamped << " of " << ref.qpos.size()
               << notes);
  // Segments follow the clip to numerical precision unless a joint limit
  // stops them (the tail); the feet stand within a few cm (the CMU walk's
  // floor itself climbs 4 cm, SOURCES.md).
  CHECK(fig.all_deg.median < 1.0);
  CHECK(fig.all_deg.p95 < 3.0);
  CHECK(fig.all_deg.max < 25.0);
  for (std::size_t k = 0; k < test::kSegmentKinds; ++k) CHECK(fig.segment_deg[k].median < 1.0);
  CHECK(fig.contact_foot_z_m.n > 0);
  CHECK(fig.contact_foot_z_m.median < 0.02);
  CHECK(fig.contact_foot_z_m.p95 < 0.035);
  CHECK(fig.contact_foot_z_m.max < 0.10);
  CHECK(fig.max_step_deg < 35.0);  // no turn-overs between frames (30 Hz punches reach 30 degrees)
  CHECK(fig.max_quat_norm_error < 1e-9);
  CHECK(fig.sign_flips == 0);
  CHECK_MESSAGE(fig.limit_violations == 0, fig.worst_violation);
  CHECK(fig.root_path_error_m < 1e-9);
}

}  // namespace

TEST_CASE("reference: CMU walk (bundled)") { check_clip("cmu_02_walk", test::bundled_clip("cmu_02_walk.bvh")); }
TEST_CASE("reference: CMU forward jumps") { check_clip("cmu_01_01_jumps", test::shared_clip("cmu_01_01_jumps.bvh")); }
TEST_CASE("reference: Bandai Namco walk") {
  check_clip("dataset-1_walk", test::shared_clip("dataset-1_walk_normal_001.bvh"));
}
TEST_CASE("reference: Bandai Namco kick") {
  check_clip("dataset-1_kick", test::shared_clip("dataset-1_kick_normal_001.bvh"));
}
TEST_CASE("reference: Bandai Namco punch") {
  check_clip("dataset-1_punch", test::shared_clip("dataset-1_punch_normal_001.bvh"));
}
TEST_CASE("reference: Bandai Namco run") {
  check_clip("dataset-2_run", test::shared_clip("dataset-2_run_normal_010.bvh"));
}
TEST_CASE("reference: Bandai Namco wave") {
  check_clip("dataset-2_wave", test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"));
}

TEST_CASE("reference: the balance stage before retargeting (tonusd's tracker.balance)") {
  const std::string path = test::bundled_clip("cmu_02_walk.bvh");
  const ClipReference off = clip_to_reference(test::humanoid(), path);
  REQUIRE_MESSAGE(off.ok(), off.error);
  CHECK(off.balance.empty());
  tonus::balance::BalanceStageOptions o;
  o.mode = tonus::balance::BalanceMode::online;
  const ClipReference online = clip_to_reference(test::humanoid(), path, o);
  REQUIRE_MESSAGE(online.ok(), online.error);
  MESSAGE(online.balance);
  CHECK(online.balance.find("balance (online, look-ahead 30 frames)") == 0);
  CHECK(online.balance.find("; under the worst estimator of the family after (") != std::string::npos);
  CHECK(online.balance.find("(not balanced under every estimator)") != std::string::npos);  // docs/balance.md
  CHECK(std::find(online.messages.begin(), online.messages.end(), online.balance) != online.messages.end());
  REQUIRE(online.qpos.size() == off.qpos.size());
  // The pelvis moves sideways and back by at most the filter's cap (8 cm per
  // axis, scaled onto the humanoid), and the root follows it.
  double largest_m = 0.0;
  for (std::size_t t = 0; t < off.qpos.size(); ++t) {
    largest_m = std::max(largest_m, std::hypot(online.qpos[t][0] - off.qpos[t][0], online.qpos[t][1] - off.qpos[t][1]));
  }
  MESSAGE("largest root shift " << largest_m << " m");
  CHECK(largest_m > 0.005);
  CHECK(largest_m < 0.08 * std::sqrt(2.0) * 1.2);

  o.lookahead_s = 0.5;
  const ClipReference refused = clip_to_reference(test::humanoid(), path, o);
  CHECK_FALSE(refused.ok());
  CHECK(refused.error.find(path + ": online balance filter") == 0);
}
