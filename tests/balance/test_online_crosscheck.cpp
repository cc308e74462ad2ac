// The streaming balance filter judged from outside: its written clip under
// the independent estimator (tests/balance/independent, no code shared with
// the filter), and how far its result lands from the offline robust filter's
// on the same clip, measured on the centre of mass both of them move.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "balance_fixtures.hpp"
#include "independent_counts.hpp"
#include "support/sanitized.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/mass_model.hpp"
#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/balance/robust_filter.hpp"

namespace tonus::balance {
namespace {

struct Distance {
  double rms_m = 0.0, max_m = 0.0;
};

// Horizontal distance between two motions' centres of mass, over the frames
// from first_frame on.
Distance com_distance(const HumanMotion& a, const HumanMotion& b, const MassModel& mass) {
  Distance d;
  std::size_t n = 0;
  for (std::size_t t = a.first_frame; t < a.size(); ++t) {
    const Vec3 ca = centre_of_mass(mass, place_segments(mass, a.frames[t].p));
    const Vec3 cb = centre_of_mass(mass, place_segments(mass, b.frames[t].p));
    const double e = (ca - cb).head<2>().norm();
    d.rms_m += e * e;
    d.max_m = std::max(d.max_m, e);
    ++n;
  }
  d.rms_m = n > 0 ? std::sqrt(d.rms_m / static_cast<double>(n)) : 0.0;
  return d;
}

struct Crosschecked {
  std::size_t independent_before = 0, independent_after = 0, independent_supported = 0;
  Distance online_to_offline, offline_edit, online_edit;
  test::PelvisHeightChange pelvis;  // the written clip's, by the independent estimator's forward kinematics
};

Crosschecked crosscheck(const std::string& name, const std::string& path, double unit_m, std::size_t first_frame) {
  const test::Loaded l = test::load(path);
  const HumanMotion& m = l.conversion.motion;
  OnlineOptions oo;
  oo.dt_s = m.dt_s;
  const OnlineRun online = run_online(m, oo);
  REQUIRE_MESSAGE(online.ok(), online.error);
  const AppliedCorrection applied = apply_correction(
      l.clip, l.conversion.geometry, m, std::vector<Vec3>(m.size(), Vec3::Zero()), online.shift_m, {}, online.drop_m);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  CHECK(applied.max_foot_displacement_m < 1e-3);  // the feet that carry weight stay
  const motion::ReadResult back = motion::parse_bvh(motion::write_bvh(applied.clip, 6));
  REQUIRE(back.ok());

  const test::IndependentCounts independent = test::independent_counts(l.clip, back.clip, unit_m, first_frame);

  const RobustFilterResult offline = robust_balance_filter(m, RobustFilterOptions{});
  REQUIRE_MESSAGE(offline.ok(), offline.error);
  const MassModel mass = make_mass_model(oo.analysis.body_mass_kg, oo.analysis.sex);
  Crosschecked c;
  c.independent_before = independent.before;
  c.independent_after = independent.after;
  c.independent_supported = independent.supported;
  c.online_to_offline = com_distance(online.corrected, offline.corrected, mass);
  c.offline_edit = com_distance(m, offline.corrected, mass);
  c.online_edit = com_distance(m, online.corrected, mass);
  c.pelvis = test::pelvis_height_change(l.clip, back.clip, unit_m, first_frame);
  MESSAGE(name << ": online filter (look-ahead " << online.lookahead_frames << " frames): independent estimator "
               << c.independent_before << " -> " << c.independent_after << " of " << c.independent_supported
               << " supported frames outside by more than 1 cm; centre of mass from the offline (robust) result: RMS "
               << 100.0 * c.online_to_offline.rms_m << " cm, max " << 100.0 * c.online_to_offline.max_m
               << " cm; the edits themselves: offline RMS " << 100.0 * c.offline_edit.rms_m << " cm (max "
               << 100.0 * c.offline_edit.max_m << "), online RMS " << 100.0 * c.online_edit.rms_m << " cm (max "
               << 100.0 * c.online_edit.max_m << "); the pelvis lowered by up to " << 1000.0 * c.pelvis.max_m
               << " mm, its vertical acceleration " << c.pelvis.max_accel_mps2 << " m/s^2 at most, p99 "
               << c.pelvis.p99_accel_mps2);
  return c;
}

}  // namespace

// Measured (release build, ctest -R crosschecked -V): the independent
// estimator's count before -> after, and the centre of mass's distance from
// the offline result (RMS, max). The ceilings sit a little above them, so a
// regression fails; they are not the goal, which the online filter
// does not meet yet (docs/balance.md, "The online filter").
TEST_CASE("online balance filter, crosschecked: Bandai walk, fewer frames outside, within 1.6 cm RMS of offline" *
          tonus::test::heavy_under_sanitizers()) {
  // 140 -> 68 of 195; 1.32 cm RMS, 4.3 max (2026-12-05, the window
  // smoothed at 10 Hz and the knee's side kept; 72 and 1.37 / 4.3 before
  // that, 82 and 1.40 / 4.3 at 6 Hz; the plain preview at 6 Hz: 81 and
  // 2.07 / 6.5).
  const Crosschecked c =
      crosscheck("Bandai walk", test::shared_clip("dataset-1_walk_normal_001.bvh"), indep::kCentimetre_m, 0);
  CHECK(c.independent_after < c.independent_before);
  CHECK(c.independent_after <= 73);
  CHECK(c.online_to_offline.rms_m < 0.016);
  CHECK(c.online_to_offline.max_m < 0.046);
  // The pelvis's drop eased (drop_envelope.hpp, and a 3 Hz follower): its
  // vertical acceleration 2.3 m/s^2 at most (8.5 frame by frame: 8 mm in one frame).
  CHECK(c.pelvis.max_accel_mps2 < 3.0);
}

TEST_CASE("online balance filter, crosschecked: Bandai kicks, fewer frames outside, within 3.2 cm RMS of offline" *
          tonus::test::heavy_under_sanitizers()) {
  // 131 -> 91 of 358; 2.85 cm RMS, 6.8 max (the window at 10 Hz, the
  // knee's side kept: the offline edit grew, 3.2 -> 3.4 cm RMS; 2.47 / 7.0
  // before it; at 6 Hz 91 and 2.47 / 6.4; the plain preview: 108 and
  // 2.41 / 6.5). The offline result's arms swinging too (2026-12-05): 3.08 /
  // 7.3.
  const Crosschecked c =
      crosscheck("Bandai kicks", test::shared_clip("dataset-1_kick_normal_001.bvh"), indep::kCentimetre_m, 0);
  CHECK(c.independent_after < c.independent_before);
  CHECK(c.independent_after <= 95);
  CHECK(c.online_to_offline.rms_m < 0.032);
  CHECK(c.online_to_offline.max_m < 0.076);
  // The pelvis's drop eased (drop_envelope.hpp, and a 3 Hz follower): p99 of its
  // vertical acceleration 3.1 m/s^2 (4.3 frame by frame); at most 6.5 (6.6), where
  // a need none of the frames before foresaw forces it.
  CHECK(c.pelvis.p99_accel_mps2 < 3.5);
}

TEST_CASE("online balance filter, crosschecked: CMU walk, fewer frames outside, within 2 cm RMS of offline" *
          tonus::test::heavy_under_sanitizers()) {
  // 73 -> 40 of 343 (2026-12-05; 75, two worse than the capture, while the
  // clip's T-pose was streamed and its flat feet on a rising floor read as a
  // heel or a forefoot alone). 1.67 cm RMS, 2.7 max: the online edit is small
  // (0.54 cm RMS) where the offline one is 1.7. The plain preview (12-04): 96
  // and 2.43 / 5.4. With the window smoothed at 10 Hz (12-05): 34, 1.66 / 2.8;
  // and the knee's side kept: 34, 1.44 / 3.3.
  const Crosschecked c = crosscheck("CMU walk", test::bundled_clip("cmu_02_walk.bvh"), indep::kCmuUnit_m, 1);
  CHECK(c.independent_after < c.independent_before);
  CHECK(c.independent_after <= 38);
  CHECK(c.online_to_offline.rms_m < 0.020);
  CHECK(c.online_to_offline.max_m < 0.035);
  // The pelvis's drop eased (drop_envelope.hpp, and a 3 Hz follower): its
  // vertical acceleration 2.5 m/s^2 at most (6.5 frame by frame, at 120 Hz).
  CHECK(c.pelvis.max_accel_mps2 < 3.0);
}

TEST_CASE("online balance filter, crosschecked: Bandai punches, fewer frames outside, within 3.1 cm RMS of offline" *
          tonus::test::heavy_under_sanitizers()) {
  // 99 -> 58 of 224; 1.77 cm RMS, 4.5 max with the window smoothed at 10 Hz
  // and the knee's side kept (12-05; 60 and 2.84 / 7.0 before that; 54 and
  // 2.91 / 6.5 at 6 Hz, where the family's worst member has 84 against 77:
  // the one clip the higher cut-off costs under this estimator). The plain preview put more frames outside under this
  // estimator than it brought in (104; 3.09 / 5.9), the boxer's bounce being
  // where the estimators part.
  const Crosschecked c =
      crosscheck("Bandai punches", test::shared_clip("dataset-1_punch_normal_001.bvh"), indep::kCentimetre_m, 0);
  CHECK(c.independent_after < c.independent_before);
  CHECK(c.independent_after <= 62);
  CHECK(c.online_to_offline.rms_m < 0.031);
  CHECK(c.online_to_offline.max_m < 0.074);
  // The pelvis's drop eased (drop_envelope.hpp, and a 3 Hz follower): its
  // vertical acceleration 0.9 m/s^2 at most (5.3 frame by frame).
  CHECK(c.pelvis.max_accel_mps2 < 3.0);
}

TEST_CASE("online balance filter, crosschecked: Bandai run, fewer frames outside, within 3.3 cm RMS of offline" *
          tonus::test::heavy_under_sanitizers()) {
  // 21 -> 15 of 35; 2.78 cm RMS, 4.4 max (2026-12-05, since the planner
  // models the support ratio: at the landings the offset's acceleration moves
  // the ZMP less than the cart-table says; 18 and 2.14 / 3.9 before): flight
  // phases leave few frames to correct (the plain preview: 21 and 3.73 / 6.8).
  // The window at 10 Hz: 14, 2.61 / 4.2; with the knee's side kept, 15 and
  // 2.88 / 7.3 (the offline result's landings moved: its edit 2.3 -> 2.1 cm
  // RMS, the largest where the two part). With the pelvis's drop eased over
  // time in both (2026-12-05): 14, 3.24 / 6.2 (the offline result now lowers
  // the pelvis over the first quarter second, for a trailing foot near the
  // floor at the first frame, where it jolted down 2 cm on that frame alone).
  const Crosschecked c =
      crosscheck("Bandai run", test::shared_clip("dataset-2_run_normal_010.bvh"), indep::kCentimetre_m, 0);
  CHECK(c.independent_after <= 16);
  CHECK(c.online_to_offline.rms_m < 0.033);
  CHECK(c.online_to_offline.max_m < 0.076);
  // The pelvis's drop eased (drop_envelope.hpp, and a 3 Hz follower): its
  // vertical acceleration 2.5 m/s^2 at most (12.5 frame by frame).
  CHECK(c.pelvis.max_accel_mps2 < 3.0);
}

TEST_CASE("online balance filter, crosschecked: Bandai waving, balanced throughout, left as it was" *
          tonus::test::heavy_under_sanitizers()) {
  const Crosschecked c = crosscheck("Bandai waving", test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"),
                                    indep::kCentimetre_m, 0);
  CHECK(c.independent_before == 0);
  CHECK(c.independent_after == 0);
  CHECK(c.online_to_offline.rms_m < 0.005);
}

}  // namespace tonus::balance
