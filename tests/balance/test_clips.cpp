// The balance filter on every shared mocap clip (two skeleton conventions:
// walks, a run, jumps, a one-leg-stance kick, punches, an idle clip): after
// the correction no analysed frame has its ZMP outside the support polygon
// (1 mm tolerance), the written clip's feet have not moved (< 1 mm), and the
// numbers are reported.
#include <doctest/doctest.h>

#include <string>

#include "balance_fixtures.hpp"
#include "support/sanitized.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/filter.hpp"

using namespace tonus::balance;

namespace {

void check_clip(const std::string& name, const std::string& path) {
  const test::Loaded l = test::load(path);
  FilterOptions o;
  const FilterResult f = balance_filter(l.conversion.motion, o);
  REQUIRE_MESSAGE(f.ok(), f.error);
  const AppliedCorrection applied = apply_correction(l.clip, l.conversion.geometry, l.conversion.motion, f.correction);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  // The written text, read back and analysed afresh (its own contacts): still balanced.
  const tonus::motion::ReadResult back = tonus::motion::parse_bvh(tonus::motion::write_bvh(applied.clip, 6));
  REQUIRE(back.ok());
  ConvertOptions same_unit;
  same_unit.metres_per_unit = l.conversion.geometry.metres_per_unit;
  const Conversion again = convert_motion(back.clip, map_skeleton(back.clip), same_unit);
  REQUIRE(again.ok());
  const Analysis reread = analyse(again.motion, o.analysis);
  REQUIRE(reread.ok());
  // No new Euler discontinuities: per rotation channel, the written file has
  // no more jumps over 90 degrees between frames than the original.
  const std::vector<std::size_t> jumps_before = test::rotation_jumps(l.clip);
  const std::vector<std::size_t> jumps_after = test::rotation_jumps(back.clip);
  REQUIRE(jumps_after.size() == jumps_before.size());
  std::size_t total_before = 0, total_after = 0;
  for (std::size_t c = 0; c < jumps_before.size(); ++c) {
    total_before += jumps_before[c];
    total_after += jumps_after[c];
    CHECK_MESSAGE(jumps_after[c] <= jumps_before[c], name << ": " << test::column_name(l.clip, c) << " jumps "
                                                          << jumps_before[c] << " -> " << jumps_after[c]);
  }
  MESSAGE(name << ": Euler jumps over 90 degrees between frames: " << total_before << " in the original, "
               << total_after << " written");
  double max_correction = 0.0;
  for (const Vec3& d : f.correction) max_correction = std::max(max_correction, d.norm());
  MESSAGE(name << ": " << f.before.summary.frames << " frames, outside before " << f.before.summary.frames_outside
               << " (max " << f.before.summary.max_outside_m << " m), after " << f.after.summary.frames_outside
               << ", after writing and re-reading " << reread.summary.frames_outside << "; airborne "
               << f.before.summary.frames_airborne << ", unsolved " << f.frames_unsolved << ", feet moved "
               << applied.max_foot_displacement_m << " m, largest waist correction " << max_correction << " rad");
  // The change figures: only what changed, and only the joints the writer sets.
  std::string largest;
  for (const JointChange& c : applied.largest_change) {
    largest += (largest.empty() ? "" : ", ") + c.joint + " " + std::to_string(c.max_rad) + " (frame " +
               std::to_string(c.frame) + ")";
    CHECK_MESSAGE(!c.bone.empty(), c.joint);
  }
  MESSAGE(name << ": RMS change over changed joints " << applied.rms_change_changed_joints_rad << " rad ("
               << applied.largest_change.size() << " joints, " << applied.changed_samples
               << " joint-frames), over every mapped joint " << applied.rms_change_all_mapped_joints_rad
               << " rad; largest per joint: " << largest);
  CHECK(applied.rms_change_changed_joints_rad >= applied.rms_change_all_mapped_joints_rad);
  CHECK(applied.largest_change.size() <= 7);  // hips, thighs, shanks, feet
  CHECK(f.after.summary.frames_outside == 0);
  CHECK(f.after.summary.max_outside_m <= o.analysis.tolerance_m);
  CHECK(reread.summary.frames_outside == 0);
  CHECK(applied.max_foot_displacement_m < 1e-3);
  CHECK(f.max_foot_displacement_m < 1e-3);
  // Airborne frames are counted apart, never as outside, and left uncorrected.
  CHECK(f.after.summary.frames_airborne == f.before.summary.frames_airborne);
  for (std::size_t t = 0; t < f.before.frames.size(); ++t) {
    if (f.before.frames[t].analysed && f.before.frames[t].airborne) CHECK(f.correction[t].norm() == 0.0);
  }
}

}  // namespace

TEST_CASE("balance: CMU walk (bundled)") { check_clip("cmu_02_walk", test::bundled_clip("cmu_02_walk.bvh")); }
TEST_CASE("balance: CMU forward jumps" * tonus::test::heavy_under_sanitizers()) {
  check_clip("cmu_01_01_jumps", test::shared_clip("cmu_01_01_jumps.bvh"));
}
TEST_CASE("balance: Bandai Namco walk") {
  check_clip("dataset-1_walk", test::shared_clip("dataset-1_walk_normal_001.bvh"));
}
TEST_CASE("balance: Bandai Namco run") {
  check_clip("dataset-2_run", test::shared_clip("dataset-2_run_normal_010.bvh"));
}
TEST_CASE("balance: Bandai Namco kicks on one leg") {
  check_clip("dataset-1_kick", test::shared_clip("dataset-1_kick_normal_001.bvh"));
}
TEST_CASE("balance: Bandai Namco punches" * tonus::test::heavy_under_sanitizers()) {
  check_clip("dataset-1_punch", test::shared_clip("dataset-1_punch_normal_001.bvh"));
}
TEST_CASE("balance: Bandai Namco waving, standing") {
  check_clip("dataset-2_wave", test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"));
}
