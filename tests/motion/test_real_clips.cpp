// The shared real clips: the facts their SOURCES.md states (frame counts and
// times, joints, channel orders, heights, distances, contacts) read through
// the reader and FK; FK invariants on every frame; FK against a separate
// rotation-matrix implementation; parse time of the 2 MB clip.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "bvh_samples.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/motion/kinematics.hpp"

using namespace tonus::motion;
using tonus::test::shared_bvh;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr double kCmuUnit_m = 0.056444;  // SOURCES.md: CMU FAQ (1/0.45) * 2.54 / 100

struct Expected {
  const char* name;
  std::size_t frames;
  double frame_time;
};

constexpr Expected kExpected[] = {
    {"cmu_02_walk.bvh", 344, 0.0083333},
    {"cmu_01_01_jumps.bvh", 2752, 0.0083333},
    {"dataset-1_walk_normal_001.bvh", 195, 0.0333333},
    {"dataset-2_run_normal_010.bvh", 80, 0.0333333},
    {"dataset-1_kick_normal_001.bvh", 358, 0.0333333},
    {"dataset-2_wave-both-hands_normal_001.bvh", 201, 0.0333333},
    {"dataset-1_punch_normal_001.bvh", 224, 0.0333333},
};

Clip load(const std::string& name) {
  ReadResult r = read_bvh_file(shared_bvh(name));
  REQUIRE_MESSAGE(r.ok(), name, ": ", r.error->line, ": ", r.error->message);
  CHECK(r.warnings.empty());
  return std::move(r.clip);
}

std::size_t joint(const Clip& clip, const char* name) {
  const std::optional<std::size_t> j = find_joint(clip, name);
  REQUIRE_MESSAGE(j.has_value(), name);
  return *j;
}

// Positions of one joint over frames [first, frame_count).
std::vector<Eigen::Vector3d> track(const Clip& clip, std::size_t j, std::size_t first = 0) {
  std::vector<Eigen::Vector3d> out;
  std::vector<JointPose> poses;
  for (std::size_t f = first; f < clip.frame_count; ++f) {
    REQUIRE(forward_kinematics(clip, f, poses));
    out.push_back(poses[j].position);
  }
  return out;
}

double min_y(const std::vector<Eigen::Vector3d>& t) {
  double m = kInf;
  for (const auto& p : t) m = std::min(m, p.y());
  return m;
}
double max_y(const std::vector<Eigen::Vector3d>& t) {
  double m = -kInf;
  for (const auto& p : t) m = std::max(m, p.y());
  return m;
}
double mean_y(const std::vector<Eigen::Vector3d>& t) {
  double s = 0.0;
  for (const auto& p : t) s += p.y();
  return s / static_cast<double>(t.size());
}
// Horizontal (x, z: the clips are Y-up) distance between first and last.
double horizontal_travel(const std::vector<Eigen::Vector3d>& t) {
  const Eigen::Vector3d d = t.back() - t.front();
  return std::hypot(d.x(), d.z());
}

// A second FK, written with rotation matrices from first principles, to
// cross-check the library's quaternion chain.
Eigen::Matrix3d elementary(int axis, double degrees) {
  const double t = degrees * std::numbers::pi / 180.0;
  const double c = std::cos(t);
  const double s = std::sin(t);
  Eigen::Matrix3d m;
  if (axis == 0) m << 1, 0, 0, 0, c, -s, 0, s, c;
  if (axis == 1) m << c, 0, s, 0, 1, 0, -s, 0, c;
  if (axis == 2) m << c, -s, 0, s, c, 0, 0, 0, 1;
  return m;
}

std::vector<Eigen::Vector3d> matrix_fk(const Clip& clip, std::size_t frame) {
  const std::size_t n = clip.channel_count();
  std::size_t col = frame * n;
  std::vector<Eigen::Matrix3d> rot(clip.joints.size());
  std::vector<Eigen::Vector3d> pos(clip.joints.size());
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const Joint& jt = clip.joints[j];
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = jt.offset;
    for (const Channel c : jt.channels) {
      const double v = clip.values[col++];
      switch (c) {
        case Channel::x_position: t.x() = v; break;
        case Channel::y_position: t.y() = v; break;
        case Channel::z_position: t.z() = v; break;
        case Channel::x_rotation: r = r * elementary(0, v); break;
        case Channel::y_rotation: r = r * elementary(1, v); break;
        case Channel::z_rotation: r = r * elementary(2, v); break;
      }
    }
    if (jt.parent < 0) {
      rot[j] = r;
      pos[j] = t;
    } else {
      const auto p = static_cast<std::size_t>(jt.parent);
      rot[j] = rot[p] * r;
      pos[j] = pos[p] + rot[p] * t;
    }
  }
  return pos;
}

}  // namespace

TEST_CASE("real clips: frame counts, frame times, joints and channel orders of SOURCES.md") {
  for (const Expected& e : kExpected) {
    CAPTURE(e.name);
    const Clip clip = load(e.name);
    CHECK(clip.frame_count == e.frames);
    CHECK(clip.frame_time_s == e.frame_time);
    CHECK(clip.values.size() == clip.frame_count * clip.channel_count());
    const bool cmu = std::string(e.name).starts_with("cmu_");
    const auto sites = static_cast<std::size_t>(
        std::count_if(clip.joints.begin(), clip.joints.end(), [](const Joint& j) { return j.end_site; }));
    CHECK(clip.joints.size() - sites == (cmu ? 31U : 22U));
    CHECK(sites == (cmu ? 7U : 5U));
    CHECK(clip.joints[0].name == (cmu ? "Hips" : "joint_Root"));
    using C = Channel;
    const std::vector<Channel> root6 = cmu ? std::vector<Channel>{C::x_position, C::y_position, C::z_position,
                                                                  C::z_rotation, C::y_rotation, C::x_rotation}
                                           : std::vector<Channel>{C::x_position, C::y_position, C::z_position,
                                                                  C::z_rotation, C::x_rotation, C::y_rotation};
    CHECK(clip.joints[0].channels == root6);
    for (std::size_t j = 1; j < clip.joints.size(); ++j) {
      const Joint& jt = clip.joints[j];
      if (jt.end_site) continue;
      if (cmu) {
        CHECK(jt.channels == std::vector<Channel>{C::z_rotation, C::y_rotation, C::x_rotation});
      } else {
        CHECK(jt.channels == root6);
      }
    }
    CHECK_FALSE(check_clip(clip).has_value());
  }
}

TEST_CASE("real clips: Bandai position channels equal the OFFSETs, joint_Root stays zero") {
  for (const Expected& e : kExpected) {
    if (std::string(e.name).starts_with("cmu_")) continue;
    CAPTURE(e.name);
    const Clip clip = load(e.name);
    const std::vector<std::size_t> col = channel_columns(clip);
    const std::size_t hips = joint(clip, "Hips");
    double worst = 0.0;
    for (std::size_t f = 0; f < clip.frame_count; ++f) {
      const std::span<const double> row = clip.frame(f);
      for (std::size_t c = 0; c < 6; ++c) CHECK(row[c] == 0.0);
      for (std::size_t j = 0; j < clip.joints.size(); ++j) {
        if (j == 0 || j == hips || clip.joints[j].end_site) continue;
        for (std::size_t k = 0; k < 3; ++k) {
          worst = std::max(worst, std::abs(row[col[j] + k] - clip.joints[j].offset[static_cast<Eigen::Index>(k)]));
        }
      }
    }
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("real clips: bone lengths are constant over every frame") {
  for (const Expected& e : kExpected) {
    CAPTURE(e.name);
    const Clip clip = load(e.name);
    const bool cmu = std::string(e.name).starts_with("cmu_");
    const std::size_t world = cmu ? 0 : joint(clip, "Hips");  // the joint carrying the world translation
    std::vector<JointPose> poses;
    double worst = 0.0;
    for (std::size_t f = 0; f < clip.frame_count; ++f) {
      REQUIRE(forward_kinematics(clip, f, poses));
      for (std::size_t j = 1; j < clip.joints.size(); ++j) {
        if (j == world) continue;
        const double length =
            (poses[j].position - poses[static_cast<std::size_t>(clip.joints[j].parent)].position).norm();
        worst = std::max(worst, std::abs(length - clip.joints[j].offset.norm()));
        CHECK(std::abs(poses[j].rotation.norm() - 1.0) < 1e-12);
      }
    }
    // CMU: rotations only, so exact to rounding; Bandai: translation channels
    // within 1e-5 of the OFFSETs (SOURCES.md).
    CHECK(worst < (cmu ? 1e-9 : 1e-4));
  }
}

TEST_CASE("real clips: FK agrees with a rotation-matrix FK written separately") {
  for (const char* name : {"cmu_02_walk.bvh", "dataset-1_kick_normal_001.bvh"}) {
    CAPTURE(name);
    const Clip clip = load(name);
    std::vector<JointPose> poses;
    double worst = 0.0;
    for (std::size_t f = 0; f < clip.frame_count; ++f) {
      REQUIRE(forward_kinematics(clip, f, poses));
      const std::vector<Eigen::Vector3d> expected = matrix_fk(clip, f);
      for (std::size_t j = 0; j < poses.size(); ++j) worst = std::max(worst, (poses[j].position - expected[j]).norm());
    }
    CHECK(worst < 1e-9);
  }
}

TEST_CASE("real clips: CMU heights, travel and toe contact in metres (SOURCES.md)") {
  const Clip walk = load("cmu_02_walk.bvh");
  const auto hips = track(walk, joint(walk, "Hips"), 1);                              // frame 0 is a T-pose
  CHECK(mean_y(hips) * kCmuUnit_m == doctest::Approx(17 * kCmuUnit_m).epsilon(0.1));  // "about 17 units"
  CHECK(horizontal_travel(hips) * kCmuUnit_m == doctest::Approx(3.4).epsilon(0.1));   // "about 3.4 m"
  const double toe = std::min(min_y(track(walk, joint(walk, "LeftToeBase_End"), 1)),
                              min_y(track(walk, joint(walk, "RightToeBase_End"), 1)));
  CHECK(toe * kCmuUnit_m > -0.02);  // "within about 1-4 cm of y=0 in contact"
  CHECK(toe * kCmuUnit_m < 0.05);
  for (const auto& p : hips) CHECK(p.y() > 0.0);

  const Clip jumps = load("cmu_01_01_jumps.bvh");
  const auto jump_hips = track(jumps, joint(jumps, "Hips"), 1);
  CHECK(min_y(jump_hips) * kCmuUnit_m == doctest::Approx(0.82).epsilon(0.05));  // "between 0.82 and 1.29 m"
  CHECK(max_y(jump_hips) * kCmuUnit_m == doctest::Approx(1.29).epsilon(0.05));
}

TEST_CASE("real clips: CMU frame 0 is a T-pose: arms stretched out sideways, near horizontal") {
  const Clip walk = load("cmu_02_walk.bvh");
  const std::vector<JointPose> p = forward_kinematics(walk, 0);
  REQUIRE_FALSE(p.empty());
  struct Arm {
    const char* shoulder;
    const char* elbow;
    const char* hand;
  };
  for (const Arm& side : {Arm{"LeftArm", "LeftForeArm", "LeftHand"}, Arm{"RightArm", "RightForeArm", "RightHand"}}) {
    CAPTURE(side.hand);
    const Eigen::Vector3d arm = p[joint(walk, side.hand)].position - p[joint(walk, side.shoulder)].position;
    // Straight: shoulder to hand is the sum of the two bone lengths.
    const double length =
        walk.joints[joint(walk, side.elbow)].offset.norm() + walk.joints[joint(walk, side.hand)].offset.norm();
    CHECK(arm.norm() == doctest::Approx(length).epsilon(1e-3));
    // Sideways and within 10 degrees of horizontal (Y is up).
    CHECK(std::abs(arm.y()) < arm.norm() * std::sin(10.0 * std::numbers::pi / 180.0));
    CHECK(std::abs(arm.x()) > 0.9 * arm.norm());
  }
  CHECK(p[joint(walk, "LeftHand")].position.x() * p[joint(walk, "RightHand")].position.x() < 0.0);  // opposite sides
}

TEST_CASE("real clips: Bandai hips, feet and travel in centimetres (SOURCES.md)") {
  const Clip wave = load("dataset-2_wave-both-hands_normal_001.bvh");
  const auto hips = track(wave, joint(wave, "Hips"));
  CHECK(mean_y(hips) == doctest::Approx(90.0).epsilon(0.07));  // "standing hip height is about 90"
  CHECK(max_y(hips) - min_y(hips) < 1.0);                      // "the hips move less than 1 cm vertically"
  for (const char* toe : {"Toes_L", "Toes_R"}) {
    CHECK(mean_y(track(wave, joint(wave, toe))) == doctest::Approx(4.2).epsilon(0.25));  // "about 4.2 cm"
  }
  for (const char* ankle : {"Foot_L", "Foot_R"}) {
    CHECK(mean_y(track(wave, joint(wave, ankle))) == doctest::Approx(12.0).epsilon(0.2));  // "about 12 cm"
  }

  const Clip walk = load("dataset-1_walk_normal_001.bvh");
  const auto walk_hips = track(walk, joint(walk, "Hips"));
  CHECK(horizontal_travel(walk_hips) == doctest::Approx(810.0).epsilon(0.06));  // "about 8.1 m"
  const double toes = std::min(min_y(track(walk, joint(walk, "Toes_L"))), min_y(track(walk, joint(walk, "Toes_R"))));
  CHECK(toes == doctest::Approx(4.2).epsilon(0.25));

  const Clip run = load("dataset-2_run_normal_010.bvh");
  const double run_m = horizontal_travel(track(run, joint(run, "Hips"))) / 100.0;
  CHECK(run_m == doctest::Approx(8.0).epsilon(0.08));  // "about 8 m at about 3.1 m/s"
  CHECK(run_m / (static_cast<double>(run.frame_count - 1) * run.frame_time_s) == doctest::Approx(3.1).epsilon(0.1));
}

TEST_CASE("real clips: parsing the 2 MB CMU clip is fast and linear in its size") {
  std::ifstream in(shared_bvh("cmu_01_01_jumps.bvh"), std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  REQUIRE(text.size() > 2'000'000);
  // Four times the frames in one text: "Frames: 2752" -> 11008.
  const std::size_t motion = text.find("Frame Time:");
  const std::size_t frames_start = text.find('\n', motion) + 1;
  std::string big = text;
  for (int i = 0; i < 3; ++i) big += text.substr(frames_start);
  const std::size_t count_at = big.find("Frames: 2752");
  REQUIRE(count_at != std::string::npos);
  big.replace(count_at, 12, "Frames: 11008");

  // The fastest of five parses of each: a busy machine (CI runs two builds'
  // tests side by side) stretches single runs, never the best one.
  using Clock = std::chrono::steady_clock;
  const auto fastest = [](const std::string& t, ReadResult& out) {
    double best = 1e9;
    for (int i = 0; i < 5; ++i) {
      const auto t0 = Clock::now();
      out = parse_bvh(t);
      best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    }
    return best;
  };
  ReadResult small, large;
  const double small_s = fastest(text, small);
  const double large_s = fastest(big, large);
  REQUIRE(small.ok());
  REQUIRE_MESSAGE(large.ok(), large.error->message);
  CHECK(large.clip.frame_count == 4 * 2752);
  MESSAGE("parse_bvh: ", text.size(), " bytes in ", small_s * 1e3, " ms; ", big.size(), " bytes in ", large_s * 1e3,
          " ms");
#if defined(NDEBUG)
  CHECK(small_s < 0.5);  // "well under a second" in release
#endif
  CHECK(large_s < 10.0 * std::max(small_s, 0.005));  // 4x the text: about 4x the time, 16x if quadratic
}
