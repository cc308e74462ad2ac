// The estimator family: shared work must not change any member's answer, and
// the verdict counts what each member sees.
#include <doctest/doctest.h>

#include "balance_fixtures.hpp"
#include "tonus/host/balance/family.hpp"

namespace tonus::balance {
namespace {

TEST_CASE("balance family: each member's analysis is the plain analysis with its options") {
  const test::Loaded l = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  const HumanMotion& motion = l.conversion.motion;
  const AnalysisOptions base;
  const std::vector<AnalysisOptions> members = estimator_family(base);
  REQUIRE(members.size() == kFamilySize);
  const Analysis reference = analyse(motion, base);
  REQUIRE(reference.ok());
  const std::vector<Analysis> family = analyse_family(motion, members, reference.contacts);
  REQUIRE(family.size() == members.size());
  double largest_spread_m = 0.0;
  for (std::size_t i = 0; i < members.size(); ++i) {
    CAPTURE(i);
    const Analysis plain = analyse(motion, members[i], &reference.contacts);
    REQUIRE(family[i].ok());
    REQUIRE(family[i].frames.size() == plain.frames.size());
    for (std::size_t t = 0; t < plain.frames.size(); ++t) {
      CHECK(family[i].frames[t].zmp_defined == plain.frames[t].zmp_defined);
      CHECK((family[i].frames[t].zmp - plain.frames[t].zmp).norm() < 1e-12);
      CHECK(family[i].frames[t].outside_m == doctest::Approx(plain.frames[t].outside_m).epsilon(1e-12));
      largest_spread_m = std::max(largest_spread_m, (family[i].frames[t].zmp - family[0].frames[t].zmp).norm());
    }
    CHECK(family[i].summary.frames_outside == plain.summary.frames_outside);
  }
  // The members are different estimators: on real capture they disagree by centimetres.
  CHECK(largest_spread_m > 0.02);
}

TEST_CASE("balance family: the verdict counts frames outside by more than the threshold, per member") {
  const test::Loaded l = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  const HumanMotion& motion = l.conversion.motion;
  const std::vector<AnalysisOptions> members = estimator_family({});
  const Analysis reference = analyse(motion, members[2]);  // 6 Hz particle: the default
  const std::vector<Analysis> family = analyse_family(motion, members, reference.contacts);
  const FamilyVerdict v = family_verdict(family, members, 0.01);
  REQUIRE(v.members.size() == members.size());
  std::size_t by_hand = 0, supported = 0;
  for (const FrameAnalysis& f : reference.frames) {
    if (!f.analysed || f.airborne || !f.zmp_defined) continue;
    ++supported;
    by_hand += f.outside_m > 0.01 ? 1U : 0U;
  }
  CHECK(v.members[2].cutoff_hz == 6.0);
  CHECK_FALSE(v.members[2].full);
  CHECK(v.members[2].supported == supported);
  CHECK(v.members[2].outside == by_hand);
  CHECK(by_hand > 20);  // the original walk is not balanced (about 100 frames)
  for (const MemberVerdict& m : v.members) CHECK(m.outside <= v.members[v.worst].outside);
  CHECK_FALSE(v.balanced());
}

TEST_CASE("balance family: a motion that is balanced under every member") {
  // The waving clip stands still on both feet: its ZMP stays well inside.
  const test::Loaded l = test::load(test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"));
  const std::vector<AnalysisOptions> members = estimator_family({});
  const Analysis reference = analyse(l.conversion.motion, members[2]);
  const FamilyVerdict v = family_verdict(analyse_family(l.conversion.motion, members, reference.contacts), members);
  for (const MemberVerdict& m : v.members) CHECK(m.outside == 0);
  CHECK(v.balanced());
}

}  // namespace
}  // namespace tonus::balance
