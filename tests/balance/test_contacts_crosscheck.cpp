// The tool's foot contacts against the independent estimator's
// (tests/balance/independent: its own thresholds, resting-height window and
// points), point by point: heel with heel, ball with toes.
#include <doctest/doctest.h>

#include <string>

#include "balance_fixtures.hpp"
#include "independent/zmp_estimator.hpp"
#include "tonus/host/balance/contacts.hpp"

namespace tonus::balance {
namespace {

double point_agreement(const std::string& path, double unit_m) {
  const test::Loaded l = test::load(path);
  const HumanMotion& m = l.conversion.motion;
  const ContactTrack tool = detect_contacts(m, ContactOptions{});
  indep::Options io;
  io.metres_per_unit = unit_m;
  io.first_frame = m.first_frame;
  const indep::Estimate e = indep::estimate_zmp(l.clip, io);
  REQUIRE(e.ok());
  REQUIRE(e.frames.size() == m.size());
  std::size_t agree = 0, total = 0;
  for (std::size_t t = m.first_frame; t < m.size(); ++t) {
    for (std::size_t f = 0; f < 2; ++f) {
      agree += (e.frames[t].contact[2 * f] == tool.frames[t][f].heel ? 1U : 0U) +
               (e.frames[t].contact[2 * f + 1] == tool.frames[t][f].ball ? 1U : 0U);
      total += 2;
    }
  }
  return static_cast<double>(agree) / static_cast<double>(total);
}

}  // namespace

TEST_CASE("contacts against the independent estimator's: the points agree, the CMU walk's rising floor too") {
  // Measured 2026-12-05: before a still, flat foot counted as down on a floor
  // higher than its resting height, the CMU walk agreed on 86.2 % of
  // point-frames (the independent detector follows the floor with a 1 s
  // window, the tool with 3 s); after, 91.0 %. The others moved by under a point.
  const std::string shared = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/";
  const double cmu_walk =
      point_agreement(std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh", indep::kCmuUnit_m);
  const double jumps = point_agreement(shared + "cmu_01_01_jumps.bvh", indep::kCmuUnit_m);
  const double bandai_walk = point_agreement(shared + "dataset-1_walk_normal_001.bvh", indep::kCentimetre_m);
  const double kicks = point_agreement(shared + "dataset-1_kick_normal_001.bvh", indep::kCentimetre_m);
  const double punches = point_agreement(shared + "dataset-1_punch_normal_001.bvh", indep::kCentimetre_m);
  MESSAGE("point-frames agreeing: CMU walk " << 100 * cmu_walk << " %, jumps " << 100 * jumps << " %, Bandai walk "
                                             << 100 * bandai_walk << " %, kicks " << 100 * kicks << " %, punches "
                                             << 100 * punches << " %");
  CHECK(cmu_walk > 0.90);
  CHECK(jumps > 0.97);
  CHECK(bandai_walk > 0.93);
  CHECK(kicks > 0.96);
  CHECK(punches > 0.86);
}

}  // namespace tonus::balance
