// The online balance filter on a streamed performer body (BodyBalance): a
// real clip streamed as a VMC sender would, checked with the test's own
// forward kinematics of the sender's skeleton (clip_stream.hpp), against the
// same filter run on the clip's own landmarks (balance::run_online, the path
// tests/balance cross-checks with an independent estimator), and under the
// estimator family.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "clip_stream.hpp"
#include "reference_checks.hpp"
#include "tonus/host/balance/family.hpp"
#include "tonus/host/reference/body_balance.hpp"

using namespace tonus;
using reference::BodyBalance;
using reference::BodySample;
using reference::test::ClipStream;
using reference::test::source_fk;
using reference::test::SourcePose;
using sim::Bone;
using sim::Vec3;

namespace {

constexpr std::size_t kN = sim::kBoneCount;
std::size_t bi(Bone b) { return sim::index(b); }

balance::OnlineOptions options_for(const ClipStream& s) {
  balance::OnlineOptions o;
  o.dt_s = s.conv.motion.dt_s;
  return o;
}

struct Streamed {
  std::vector<BodySample> out;
  std::vector<balance::OnlineFrame> frames;
  std::size_t lookahead = 0;
};

Streamed stream_through(const ClipStream& s) {
  BodyBalance::Created made = BodyBalance::create(s.skeleton, options_for(s));
  REQUIRE_MESSAGE(made, made.error);
  BodyBalance& b = *made.balance;
  Streamed r;
  r.lookahead = b.lookahead_frames();
  BodySample out;
  balance::OnlineFrame f;
  for (std::size_t k = 0; k < s.samples.size(); ++k) {
    const bool emitted = b.push(s.samples[k], out, &f);
    CHECK(emitted == (k >= r.lookahead));
    if (!emitted) continue;
    r.out.push_back(out);
    r.frames.push_back(f);
  }
  while (b.flush(out, &f)) {
    r.out.push_back(out);
    r.frames.push_back(f);
  }
  CHECK(b.invalid_samples() == 0);
  return r;
}

// The corrected stream as landmarks, for the analysis.
balance::HumanMotion landmarks_of(const ClipStream& s, const std::vector<BodySample>& samples) {
  BodyBalance::Created made = BodyBalance::create(s.skeleton, options_for(s));
  REQUIRE(made);
  balance::HumanMotion m;
  m.dt_s = s.conv.motion.dt_s;
  m.first_frame = s.conv.motion.first_frame;
  for (const BodySample& x : samples) m.frames.push_back(made.balance->landmarks(x));
  return m;
}

balance::MemberVerdict worst(const balance::HumanMotion& m, const balance::ContactTrack& contacts) {
  const std::vector<balance::AnalysisOptions> members = balance::estimator_family(balance::AnalysisOptions{});
  const balance::FamilyVerdict v = balance::family_verdict(balance::analyse_family(m, members, contacts), members);
  return v.members[v.worst];
}

// `same_landmarks`: the clip's skeleton is all humanoid bones and has no End
// Sites, so streaming it loses nothing and both paths must agree to rounding.
// Otherwise (CMU: spine and neck joints between the humanoid's, End Sites at
// the head top, fingertips and toes) the stream is a different body, and the
// corrections agree only to what that moves the ZMP.
void check_clip(const std::string& name, const std::string& path, bool same_landmarks) {
  const ClipStream s = reference::test::stream_clip(path);
  const Streamed r = stream_through(s);
  const std::size_t n = s.samples.size();
  REQUIRE(r.out.size() == n);

  // Frame by frame, with the test's own forward kinematics of the sender's skeleton.
  double max_foot_m = 0.0, max_hip_vs_shift_m = 0.0, max_upper_change = 0.0, max_shift_m = 0.0;
  std::size_t planted = 0;
  for (std::size_t k = 0; k < n; ++k) {
    REQUIRE(r.frames[k].index == k);
    const SourcePose before = source_fk(s.skeleton, s.samples[k]);
    const SourcePose after = source_fk(s.skeleton, r.out[k]);
    const balance::OnlineFrame& f = r.frames[k];
    // The hips move by the filter's shift and drop, nothing else.
    const Vec3 moved = after.pos[0] - before.pos[0];
    max_hip_vs_shift_m = std::max(max_hip_vs_shift_m, (moved - Vec3(f.shift_m.x(), f.shift_m.y(), -f.drop_m)).norm());
    max_shift_m = std::max(max_shift_m, f.shift_m.norm());
    // Above the hips, every local rotation is the sender's.
    for (const Bone b :
         {Bone::Spine, Bone::Chest, Bone::Neck, Bone::Head, Bone::LeftUpperArm, Bone::RightLowerArm, Bone::LeftHand}) {
      if (!s.skeleton.present[bi(b)]) continue;
      max_upper_change = std::max(max_upper_change, r.out[k].local[bi(b)].angularDistance(s.samples[k].local[bi(b)]));
    }
    // A foot that is down keeps its ankle and its toes.
    for (std::size_t side = 0; side < 2; ++side) {
      if (!f.contacts[side].any() || !f.reachable) continue;
      ++planted;
      for (const Bone b :
           {side == 0 ? Bone::LeftFoot : Bone::RightFoot, side == 0 ? Bone::LeftToes : Bone::RightToes}) {
        if (s.skeleton.present[bi(b)]) max_foot_m = std::max(max_foot_m, (after.pos[bi(b)] - before.pos[bi(b)]).norm());
      }
    }
  }

  // The same filter on the clip's own landmarks: the pelvis shifts alike.
  balance::OnlineOptions o = options_for(s);
  const balance::OnlineRun clip_run = balance::run_online(s.conv.motion, o);
  REQUIRE(clip_run.ok());
  REQUIRE(clip_run.shift_m.size() == n);
  double sq = 0.0, max_gap = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = (clip_run.shift_m[k] - r.frames[k].shift_m).norm();
    sq += d * d;
    max_gap = std::max(max_gap, d);
  }
  const double rms_gap = std::sqrt(sq / static_cast<double>(n));

  // Under the estimator family, on the landmarks of what went in and what came out.
  const balance::HumanMotion in_motion = landmarks_of(s, s.samples);
  double landmark_gap_m = 0.0;  // the stream's landmarks against the clip's
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t l = 0; l < balance::kLandmarkCount; ++l)
      landmark_gap_m = std::max(landmark_gap_m, (in_motion.frames[k].p[l] - s.conv.motion.frames[k].p[l]).norm());
  }
  const balance::HumanMotion out_motion = landmarks_of(s, r.out);
  const balance::ContactTrack contacts = balance::detect_contacts(in_motion, balance::ContactOptions{});
  const balance::MemberVerdict before = worst(in_motion, contacts);
  const balance::MemberVerdict after = worst(out_motion, contacts);

  MESSAGE(name << ": " << n << " samples, look-ahead " << r.lookahead << " frames; hips off the filter's shift by "
               << max_hip_vs_shift_m << " m (largest shift " << max_shift_m << " m); planted feet moved " << max_foot_m
               << " m over " << planted << " foot-frames; upper body turned " << max_upper_change
               << " rad; shift against the clip path's: RMS " << rms_gap << " m, max " << max_gap
               << " m (landmarks apart by up to " << landmark_gap_m << " m); worst member of the family: "
               << before.outside << " -> " << after.outside << " of " << before.supported << " supported frames ("
               << after.cutoff_hz << " Hz " << std::string(after.full ? "full" : "particle") << ")");
  CHECK(max_hip_vs_shift_m < 1e-9);
  CHECK(max_shift_m > 0.005);  // it did correct something
  CHECK(planted > n / 2);
  CHECK(max_foot_m < 1e-9);
  CHECK(max_upper_change < 1e-9);
  if (same_landmarks) {
    CHECK(landmark_gap_m < 1e-5);  // the sender's quaternions renormalised
    CHECK(max_gap < 1e-6);
  } else {
    CHECK(rms_gap < 0.015);
  }
  CHECK(after.outside < before.outside);
}

}  // namespace

TEST_CASE("body balance: the Bandai Namco walk streamed as a VMC performer, corrected online") {
  check_clip("Bandai walk", reference::test::shared_clip("dataset-1_walk_normal_001.bvh"), true);
}

TEST_CASE("body balance: the CMU walk streamed as a VMC performer, corrected online (bundled)") {
  check_clip("CMU walk", reference::test::bundled_clip("cmu_02_walk.bvh"), false);
}

TEST_CASE("body balance: bad input is refused or held, never a crash nor a non-finite value") {
  const ClipStream s = reference::test::stream_clip(reference::test::bundled_clip("cmu_02_walk.bvh"));
  SUBCASE("a skeleton without a leg, or options the filter refuses") {
    reference::SourceSkeleton legless = s.skeleton;
    legless.present[bi(Bone::LeftLowerLeg)] = false;
    const BodyBalance::Created a = BodyBalance::create(legless, options_for(s));
    CHECK_FALSE(a);
    CHECK(a.error.find("LeftLowerLeg") != std::string::npos);
    reference::SourceSkeleton nan_offset = s.skeleton;
    nan_offset.offset[bi(Bone::Spine)].x() = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(BodyBalance::create(nan_offset, options_for(s)));
    balance::OnlineOptions o = options_for(s);
    o.lookahead_s = 0.5;
    const BodyBalance::Created b = BodyBalance::create(s.skeleton, o);
    CHECK_FALSE(b);
    CHECK(b.error.find("look-ahead") != std::string::npos);
    o = options_for(s);
    o.dt_s = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(BodyBalance::create(s.skeleton, o));
  }
  SUBCASE("NaN, non-unit and absent values keep the last valid ones") {
    BodyBalance::Created made = BodyBalance::create(s.skeleton, options_for(s));
    REQUIRE(made);
    BodyBalance& b = *made.balance;
    BodySample out;
    std::size_t emitted = 0, bad = 0;
    for (std::size_t k = 0; k < s.samples.size(); ++k) {
      BodySample in = s.samples[k];
      if (k % 7 == 3) {
        in.root_position.y() = std::numeric_limits<double>::quiet_NaN();
        ++bad;
      } else if (k % 7 == 5) {
        in.local[bi(Bone::LeftLowerLeg)].coeffs() *= 3.0;  // not unit
        ++bad;
      } else if (k % 7 == 6) {
        in.present.fill(false);  // nothing but the root
      }
      if (!b.push(in, out)) continue;
      ++emitted;
      const SourcePose p = source_fk(s.skeleton, out);
      for (std::size_t i = 0; i < kN; ++i) {
        if (s.skeleton.present[i]) REQUIRE(sim::all_finite(p.pos[i]));
      }
      // The held values came through: the output's knee is the last valid one's, not the tripled quaternion.
      CHECK(std::abs(out.local[bi(Bone::LeftLowerLeg)].norm() - 1.0) < 1e-9);
    }
    CHECK(emitted == s.samples.size() - b.lookahead_frames());
    CHECK(b.invalid_samples() == bad);
  }
}
