// The robust balance filter (issue 14's second design), checked on real
// clips by every estimator of the family, after writing and re-reading the
// BVH, and by the independent estimator (tests/balance/independent), which
// shares no code with the filter.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "balance_fixtures.hpp"
#include "independent_counts.hpp"
#include "support/sanitized.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/robust_filter.hpp"

namespace tonus::balance {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct Checked {
  FamilyVerdict written;   // the written clip, read back, its own contacts
  FamilyVerdict straight;  // ... under the family with the trunk straight (mass_model.hpp)
  std::size_t independent_before = 0;
  std::size_t independent_after = 0;
  std::size_t independent_supported = 0;
  test::ContactTiming timing;       // of the independent estimator's frames outside after
  test::PelvisHeightChange pelvis;  // the written clip's, by the independent estimator's forward kinematics
  test::SiteJerks jerk;             // the pelvis's and the neck's horizontal jerk, the same way
};

// The share of the independent estimator's frames outside after that sit
// within 0.1 s of its contact changes, over the share of all its supported
// frames that do: above 1, the disagreement gathers at heel strikes and toe-offs.
double concentration_at_contact_changes(const test::ContactTiming& t) {
  if (t.outside == 0 || t.defined_near_change == 0) return 0.0;
  return (static_cast<double>(t.outside_near_change) / static_cast<double>(t.outside)) /
         (static_cast<double>(t.defined_near_change) / static_cast<double>(t.defined));
}

// The correction adds no jitter where it should not: the written clip's
// horizontal jerk of the pelvis and the neck (RMS, unsmoothed, the independent
// estimator's forward kinematics) over the capture's, at most `limit`.
void check_no_added_jitter(const test::SiteJerks& j, double limit) {
  CHECK(j.pelvis.rms_after_mps3 <= limit * j.pelvis.rms_before_mps3);
  CHECK(j.neck.rms_after_mps3 <= limit * j.neck.rms_before_mps3);
}

Checked run(const std::string& name, const std::string& path, double unit_m, std::size_t first_frame,
            const RobustFilterOptions& o) {
  const test::Loaded l = test::load(path);
  const RobustFilterResult r = robust_balance_filter(l.conversion.motion, o);
  REQUIRE_MESSAGE(r.ok(), r.error);
  const AppliedCorrection applied = apply_correction(l.clip, l.conversion.geometry, l.conversion.motion, r.rotation,
                                                     r.shift_m, r.follow, r.drop_m, r.arm_swing_rad);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  const motion::ReadResult back = motion::parse_bvh(motion::write_bvh(applied.clip, 6));
  REQUIRE(back.ok());
  ConvertOptions same_unit;
  same_unit.metres_per_unit = l.conversion.geometry.metres_per_unit;
  const Conversion again = convert_motion(back.clip, map_skeleton(back.clip), same_unit);
  REQUIRE(again.ok());
  Checked c;
  const ContactTrack contacts_back = detect_contacts(again.motion, o.analysis.contacts);
  c.written = family_verdict(analyse_family(again.motion, r.members, contacts_back), r.members);
  AnalysisOptions straight_base = o.analysis;
  straight_base.trunk = TrunkModel::straight;
  const std::vector<AnalysisOptions> straight_members = estimator_family(straight_base);
  c.straight = family_verdict(analyse_family(again.motion, straight_members, contacts_back), straight_members);

  // The feet that carry weight keep their captured pose; caps hold.
  CHECK(applied.max_foot_displacement_m < 1e-3);
  CHECK(r.max_foot_displacement_m < 1e-3);
  CHECK(r.max_lean_rad <= o.max_lean_rad + 1e-9);
  CHECK(r.max_yaw_rad <= o.max_yaw_rad + 1e-9);
  CHECK(r.max_shift_m <= o.max_shift_m + o.max_fine_shift_m + 1e-9);
  CHECK(r.max_arm_swing_rad <= o.max_arm_swing_rad + 1e-9);
  // No new Euler discontinuities in the written file, away from gimbal lock:
  // the kicks' hips pass within 1.5 degrees of it at frame 75 of one result
  // (the capture within 5 degrees, its first and last angles turning 77
  // degrees a frame there), where no representation avoids a swing.
  const std::vector<std::size_t> jumps_before = test::rotation_jumps(l.clip, 90.0, 5.0),
                                 jumps_after = test::rotation_jumps(back.clip, 90.0, 5.0);
  for (std::size_t k = 0; k < jumps_before.size(); ++k)
    CHECK_MESSAGE(jumps_after[k] <= jumps_before[k], name << ": " << test::column_name(back.clip, k));

  // Local: a frame inside by 2 cm under every member, more than 0.3 s from
  // any frame that is outside under some member, keeps its trunk's
  // orientation, and its arms, within 1 degree.
  const std::size_t n = l.conversion.motion.size();
  std::vector<bool> needs(n, false), comfortable(n, true);
  for (const Analysis& a : r.before) {
    for (std::size_t t = 0; t < n; ++t) {
      const FrameAnalysis& f = a.frames[t];
      if (!f.analysed || f.airborne || !f.zmp_defined) {
        comfortable[t] = false;
        continue;
      }
      needs[t] = needs[t] || f.outside_m > 0.0;
      comfortable[t] = comfortable[t] && f.outside_m <= -0.02;
    }
  }
  const auto reach = static_cast<std::ptrdiff_t>(std::ceil(0.3 / l.conversion.motion.dt_s));
  std::size_t far = 0, far_turned = 0;
  double far_max = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    if (!comfortable[t]) continue;
    bool near = false;
    for (std::ptrdiff_t d = -reach; d <= reach && !near; ++d) {
      const std::ptrdiff_t u = static_cast<std::ptrdiff_t>(t) + d;
      near = u >= 0 && u < static_cast<std::ptrdiff_t>(n) && needs[static_cast<std::size_t>(u)];
    }
    if (near) continue;
    ++far;
    const double turned = std::max(r.rotation[t].norm(), r.arm_swing_rad[t].cwiseAbs().maxCoeff());
    far_max = std::max(far_max, turned);
    far_turned += turned > kDegree ? 1U : 0U;
  }
  CHECK_MESSAGE(far_turned == 0, name << ": " << far_turned << " of " << far
                                      << " far, comfortable frames turned by more "
                                      << "than 1 degree (largest " << far_max / kDegree << ")");

  const test::IndependentCounts independent = test::independent_counts(l.clip, back.clip, unit_m, first_frame);
  c.independent_before = independent.before;
  c.independent_after = independent.after;
  c.independent_supported = independent.supported;
  c.timing = test::contact_timing(back.clip, unit_m, first_frame);
  c.pelvis = test::pelvis_height_change(l.clip, back.clip, unit_m, first_frame);
  c.jerk = test::horizontal_jerks(l.clip, back.clip, unit_m, first_frame);

  std::string members;
  for (std::size_t i = 0; i < c.written.members.size(); ++i) {
    const MemberVerdict& m = c.written.members[i];
    members += (i == 0 ? "" : ", ") + std::to_string(static_cast<int>(m.cutoff_hz)) + (m.full ? "f" : "p") +
               (m.trunk == TrunkModel::straight ? "s " : " ") + std::to_string(r.verdict_before.members[i].outside) +
               "->" + std::to_string(m.outside);
  }
  std::string straight;
  for (const MemberVerdict& m : c.straight.members)
    straight += (straight.empty() ? "" : ", ") + std::to_string(static_cast<int>(m.cutoff_hz)) +
                (m.full ? "f " : "p ") + std::to_string(m.outside);
  MESSAGE(name << ": the written clip under the family with the trunk straight: " << straight);
  MESSAGE(name << ": frames outside by more than 1 cm, before -> written, of " << c.written.members[0].supported << ": "
               << members << "; independent " << c.independent_before << " -> " << c.independent_after << " of "
               << c.independent_supported << "; lean " << r.max_lean_rad / kDegree << " deg, yaw "
               << r.max_yaw_rad / kDegree << " deg, shift " << 100.0 * r.max_shift_m << " cm, arms "
               << r.max_arm_swing_rad / kDegree << " deg; far frames " << far << ", largest turn there "
               << far_max / kDegree << " deg; " << r.iterations << " iterations");
  MESSAGE(name << ": independent estimator after: " << c.timing.outside_near_change << " of its " << c.timing.outside
               << " frames outside within 0.1 s of one of its contact changes (" << c.timing.defined_near_change
               << " of its " << c.timing.defined << " supported frames are), concentration "
               << concentration_at_contact_changes(c.timing) << "; " << c.timing.outside_fast_landing
               << " outside when a foot point lands at up to 0.8 m/s");
  MESSAGE(name << ": the pelvis lowered by up to " << 1000.0 * c.pelvis.max_m << " mm, its vertical acceleration "
               << c.pelvis.max_accel_mps2 << " m/s^2 at most, p99 " << c.pelvis.p99_accel_mps2);
  MESSAGE(name << ": horizontal jerk, capture -> written, RMS (p99), m/s^3: pelvis " << c.jerk.pelvis.rms_before_mps3
               << " (" << c.jerk.pelvis.p99_before_mps3 << ") -> " << c.jerk.pelvis.rms_after_mps3 << " ("
               << c.jerk.pelvis.p99_after_mps3 << "), neck " << c.jerk.neck.rms_before_mps3 << " ("
               << c.jerk.neck.p99_before_mps3 << ") -> " << c.jerk.neck.rms_after_mps3 << " ("
               << c.jerk.neck.p99_after_mps3 << ")");
  return c;
}

TEST_CASE("robust balance filter: Bandai Namco walk, balanced under every estimator of the family") {
  const Checked c = run("Bandai walk", test::shared_clip("dataset-1_walk_normal_001.bvh"), indep::kCentimetre_m, 0, {});
  for (const MemberVerdict& m : c.written.members) CHECK(m.share() <= kFamilyAllowedShare);
  CHECK(c.written.balanced());
  // The independent estimator disagrees at heel strikes (its heel lands one
  // or two frames later, so the ZMP, already on the landing heel, is ahead of
  // its support): measured 39 of 195 (140 before). The goal (2 %) is not met.
  CHECK(c.independent_after <= 45);
  CHECK(c.independent_after * 3 < c.independent_before);
  // Measured: 36 of the 39 within 0.1 s of its contact changes (117 of 195
  // frames are), concentration 1.54; 23 with landings called at up to 0.8 m/s.
  CHECK(concentration_at_contact_changes(c.timing) > 1.4);
  CHECK(c.timing.outside_fast_landing * 10 < c.timing.outside * 7);
  // The pelvis's drop eased over time (drop_envelope.hpp): measured 0.3 m/s^2
  // at most; frame by frame, the drop jolted it by 2.8 m/s^2 (3 mm in a frame).
  CHECK(c.pelvis.max_accel_mps2 < 1.0);
  // Measured 2026-12-05: pelvis 80.5 -> 79.7 m/s^3 RMS, neck 73.4 -> 63.4.
  check_no_added_jitter(c.jerk, 1.02);
}

// Where the trunk's mass lies moves the ZMP as much as the smoothing does
// (docs/balance.md, "The trunk model"): the Bandai walk corrected under the
// family alone leaves 31-32 of 195 frames outside under its 12 Hz members
// with the trunk straight. Corrected under both, it is balanced under all 16.
TEST_CASE("robust balance filter, both trunks: Bandai Namco walk, balanced under the family with either trunk") {
  RobustFilterOptions o;
  o.both_trunks = true;
  const Checked c =
      run("Bandai walk, both trunks", test::shared_clip("dataset-1_walk_normal_001.bvh"), indep::kCentimetre_m, 0, o);
  REQUIRE(c.written.members.size() == 2 * kFamilySize);
  std::size_t straight_members = 0;
  for (const MemberVerdict& m : c.written.members) {
    CHECK(m.share() <= kFamilyAllowedShare);
    straight_members += m.trunk == TrunkModel::straight ? 1U : 0U;
  }
  CHECK(straight_members == kFamilySize);
  for (const MemberVerdict& m : c.straight.members) CHECK(m.share() <= kFamilyAllowedShare);
  // The independent estimator, whose trunk is rigid, finds fewer frames
  // outside than after the spine-only correction (measured 31 against 35).
  CHECK(c.independent_after <= 33);
}

TEST_CASE("robust balance filter: CMU walk (bundled), most frames balanced under every estimator" *
          tonus::test::heavy_under_sanitizers()) {
  RobustFilterOptions o;
  o.max_iterations = 40;
  const Checked c = run("CMU walk", test::bundled_clip("cmu_02_walk.bvh"), indep::kCmuUnit_m, 1, o);
  // Measured: at most 18 of 342 under the worst member (4 Hz; 226 before
  // under the worst, 12 Hz), 33 of 343 under the independent estimator (73
  // before). The goal (2 %, 7 frames) is not met.
  CHECK(c.written.members[c.written.worst].outside <= 20);
  CHECK(c.independent_after <= 40);
  CHECK(c.independent_after < c.independent_before);
  // Measured: all 33 within 0.1 s of its contact changes (206 of 343 frames
  // are), concentration 1.67; 8 with landings called at up to 0.8 m/s.
  CHECK(concentration_at_contact_changes(c.timing) > 1.4);
  CHECK(c.timing.outside_fast_landing * 2 < c.timing.outside);
  CHECK(c.pelvis.max_accel_mps2 < 2.0);
  // Measured 2026-12-05 (the capture's 120 Hz jitter dominates): pelvis
  // 5194 -> 5176 m/s^3 RMS, neck 2390 -> 2405.
  check_no_added_jitter(c.jerk, 1.02);
}

TEST_CASE("robust balance filter: Bandai Namco punches, cheap arm swings take the 6-12 Hz members in" *
          tonus::test::heavy_under_sanitizers()) {
  // The worst frames under 6-12 Hz, with the waist alone and with the arms
  // swinging too, weighted low (0.01 per radian, a tenth of the default); the
  // 4 Hz members stay the limit (the lunges' landings, docs/balance.md), so
  // the clip is not balanced either way.
  const auto worst_above_4hz = [](const FamilyVerdict& v) {
    std::size_t w = 0;
    for (const MemberVerdict& m : v.members) w = std::max(w, m.cutoff_hz > 5.0 ? m.outside : std::size_t{0});
    return w;
  };
  RobustFilterOptions waist_only;
  waist_only.max_arm_swing_rad = 0.0;
  const std::string path = test::shared_clip("dataset-1_punch_normal_001.bvh");
  const Checked without = run("Bandai punches, waist only", path, indep::kCentimetre_m, 0, waist_only);
  RobustFilterOptions cheap_arms;
  cheap_arms.arm_weight = 0.01;
  const Checked with = run("Bandai punches, cheap arms", path, indep::kCentimetre_m, 0, cheap_arms);
  MESSAGE("worst member above 4 Hz: " << worst_above_4hz(without.written) << " -> " << worst_above_4hz(with.written)
                                      << "; worst member: " << without.written.members[without.written.worst].outside
                                      << " -> " << with.written.members[with.written.worst].outside << " of "
                                      << with.written.members[0].supported);
  CHECK(worst_above_4hz(with.written) * 3 <= worst_above_4hz(without.written));
  CHECK(with.written.members[with.written.worst].outside < without.written.members[without.written.worst].outside);
  CHECK(with.independent_after < with.independent_before);
  // The punches' pelvis comes out jerkier (RMS 98 -> 113 m/s^3 with the waist
  // alone, 110 with cheap arms; the neck 98 -> 92 and 95): the 0.1 s knots'
  // lean and shift, not the fine layer (without it, 1.28 times in a scratch
  // run). Held so it grows no further.
  check_no_added_jitter(without.jerk, 1.2);
  check_no_added_jitter(with.jerk, 1.2);
}

TEST_CASE("robust balance filter: Bandai Namco kicks, the kicking leg swings with the body" *
          tonus::test::heavy_under_sanitizers()) {
  const Checked c =
      run("Bandai kicks", test::shared_clip("dataset-1_kick_normal_001.bvh"), indep::kCentimetre_m, 0, {});
  // Measured (40 iterations): at most 8 of 358 under the worst member (12 Hz
  // particle; 148 before), 64 under the independent estimator (131 before).
  // With the swinging foot kept where the capture has it, the worst member found 84.
  CHECK(c.written.members[c.written.worst].outside <= 12);
  CHECK(c.written.members[c.written.worst].share() <= 0.035);
  // 62 since the arms swing (2026-12-05; 70 before).
  CHECK(c.independent_after <= 72);
  // Measured: 42 of the 64 within 0.1 s of its contact changes (133 of 358
  // frames are), concentration 1.77; but 62 with landings called at up to
  // 0.8 m/s: here the landing threshold is not what disagrees.
  CHECK(concentration_at_contact_changes(c.timing) > 1.4);
  // The drop eased over time: frame by frame it moved the pelvis 10 mm
  // between two frames, 14 m/s^2 (the tool, 100 iterations; 1.9 now).
  CHECK(c.pelvis.max_accel_mps2 < 2.5);
  // Measured 2026-12-05: pelvis 131 -> 128 m/s^3 RMS (p99 546 -> 390), neck
  // 117 -> 105.
  check_no_added_jitter(c.jerk, 1.02);
}

TEST_CASE("robust balance filter: a clip balanced under every estimator is left exactly as it is") {
  // The waving clip stands on both feet with its ZMP well inside throughout.
  const test::Loaded l = test::load(test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"));
  const RobustFilterResult r = robust_balance_filter(l.conversion.motion, {});
  REQUIRE(r.ok());
  CHECK(r.verdict_before.balanced());
  double largest = 0.0;
  for (std::size_t t = 0; t < r.rotation.size(); ++t)
    largest = std::max({largest, r.rotation[t].norm(), r.shift_m[t].norm(), r.drop_m[t]});
  CHECK(largest == 0.0);
  CHECK(r.frames_unsolved == 0);
}

TEST_CASE("robust balance filter: absurd options are refused with a message") {
  const test::Loaded l = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  RobustFilterOptions o;
  o.knot_spacing_s = 0.0;
  CHECK_FALSE(robust_balance_filter(l.conversion.motion, o).ok());
  o = {};
  o.margin_m = std::nan("");
  CHECK_FALSE(robust_balance_filter(l.conversion.motion, o).ok());
  o = {};
  o.max_shift_m = -1.0;
  CHECK_FALSE(robust_balance_filter(l.conversion.motion, o).ok());
}

}  // namespace
}  // namespace tonus::balance
