// Foot contacts on real clips, against what their SOURCES.md says of them.
#include <doctest/doctest.h>

#include "balance_fixtures.hpp"
#include "tonus/host/balance/analysis.hpp"

using namespace tonus::balance;

namespace {

struct Phases {
  std::size_t frames = 0, double_support = 0, left = 0, right = 0, airborne = 0, single_phases = 0;
};

Phases phases(const std::string& path) {
  const test::Loaded l = test::load(path);
  const ContactTrack track = detect_contacts(l.conversion.motion, ContactOptions{});
  Phases p;
  int last = -1;  // 0 left only, 1 right only, 2 both, 3 none
  for (std::size_t t = l.conversion.motion.first_frame; t < track.frames.size(); ++t) {
    const bool lf = track.frames[t][0].any(), rf = track.frames[t][1].any();
    const int state = lf && rf ? 2 : (lf ? 0 : (rf ? 1 : 3));
    ++p.frames;
    p.double_support += state == 2 ? 1 : 0;
    p.left += state == 0 ? 1 : 0;
    p.right += state == 1 ? 1 : 0;
    p.airborne += state == 3 ? 1 : 0;
    if ((state == 0 || state == 1) && state != last) ++p.single_phases;
    last = state;
  }
  return p;
}

}  // namespace

TEST_CASE("contacts: a walk alternates single support with short double support, never flies") {
  const Phases p = phases(test::shared_clip("dataset-1_walk_normal_001.bvh"));
  MESSAGE("walk: " << p.single_phases << " single-support phases, " << p.double_support << " double, " << p.airborne
                   << " airborne of " << p.frames);
  // SOURCES.md: about 13 alternating single-support phases, 8-12 % double support, no flight.
  CHECK(p.single_phases >= 11);
  CHECK(p.single_phases <= 15);
  CHECK(p.airborne == 0);
  CHECK(p.double_support > p.frames / 20);
  CHECK(p.double_support < p.frames / 4);
}

TEST_CASE("contacts: a run has flight phases and no double support, standing never lifts a foot") {
  const Phases run = phases(test::shared_clip("dataset-2_run_normal_010.bvh"));
  MESSAGE("run: " << run.airborne << " airborne, " << run.double_support << " double of " << run.frames);
  CHECK(run.airborne > run.frames / 3);  // about half by a simple test (SOURCES.md)
  CHECK(run.airborne < 2 * run.frames / 3);
  CHECK(run.double_support < run.frames / 20);
  const Phases wave = phases(test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"));
  CHECK(wave.double_support == wave.frames);
}

TEST_CASE("contacts: one-leg kicks stand on the left foot, jumps fly about a fifth of the time") {
  const Phases kick = phases(test::shared_clip("dataset-1_kick_normal_001.bvh"));
  MESSAGE("kick: left only " << kick.left << ", right only " << kick.right << " of " << kick.frames);
  CHECK(kick.left > kick.frames / 6);  // about 25 % left-foot-only (SOURCES.md)
  CHECK(kick.left > 3 * kick.right);
  const Phases jumps = phases(test::shared_clip("cmu_01_01_jumps.bvh"));
  MESSAGE("jumps: airborne " << jumps.airborne << " of " << jumps.frames);
  CHECK(jumps.airborne > jumps.frames / 8);  // about 20 % (SOURCES.md)
  CHECK(jumps.airborne < jumps.frames / 3);
}

TEST_CASE("contacts: a leading T-pose is nobody's neighbour: the contacts after it are as without it") {
  // The CMU walk starts with a T-pose frame, 5 cm lower and elsewhere; a
  // central difference across it made the first frame of motion a flight.
  const test::Loaded l = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  const HumanMotion& m = l.conversion.motion;
  REQUIRE(m.first_frame == 1);
  const ContactTrack with_tpose = detect_contacts(m, ContactOptions{});
  const ContactTrack alone = detect_contacts(test::without_leading_tpose(m), ContactOptions{});
  std::size_t same = 0;
  for (std::size_t t = 1; t < m.size(); ++t) {
    for (std::size_t f = 0; f < 2; ++f) {
      same += with_tpose.frames[t][f].heel == alone.frames[t - 1][f].heel &&
              with_tpose.frames[t][f].ball == alone.frames[t - 1][f].ball;
    }
  }
  CHECK(same == 2 * (m.size() - 1));
  CHECK(with_tpose.frames[1][1].any());  // the right forefoot is down as the take starts
  CHECK_FALSE(with_tpose.frames[0][0].any());
  CHECK_FALSE(with_tpose.frames[0][1].any());
}
