// From BVH clips to the balance analysis: unit guesses, the leading T-pose,
// skeleton conventions and mapping overrides, channel orders, and clear
// refusals.
#include <doctest/doctest.h>

#include <cmath>

#include "balance_fixtures.hpp"
#include "tonus/host/balance/analysis.hpp"
#include "tonus/host/motion/kinematics.hpp"

using namespace tonus::balance;
namespace motion = tonus::motion;

namespace {

// The clip with every length scaled (offsets and position channels).
motion::Clip scaled(motion::Clip c, double factor) {
  const std::vector<std::size_t> cols = motion::channel_columns(c);
  for (motion::Joint& j : c.joints) j.offset *= factor;
  for (std::size_t f = 0; f < c.frame_count; ++f) {
    auto row = c.frame(f);
    for (std::size_t j = 0; j < c.joints.size(); ++j) {
      for (std::size_t k = cols[j]; k < cols[j + 1]; ++k) {
        if (!motion::is_rotation(c.joints[j].channels[k - cols[j]])) row[k] *= factor;
      }
    }
  }
  return c;
}

double zmp_outside_total(const motion::Clip& clip, const ConvertOptions& opt = {}) {
  const Conversion conv = convert_motion(clip, map_skeleton(clip), opt);
  REQUIRE_MESSAGE(conv.ok(), conv.error);
  const Analysis a = analyse(conv.motion, AnalysisOptions{});
  REQUIRE(a.ok());
  double sum = 0.0;
  for (const FrameAnalysis& f : a.frames) sum += f.analysed && !f.airborne ? f.outside_m : 0.0;
  return sum;
}

}  // namespace

TEST_CASE("convert: the unit is guessed from the leg length, and a given unit wins") {
  const test::Loaded cmu = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  CHECK(cmu.conversion.unit_guessed);
  CHECK(cmu.conversion.geometry.metres_per_unit == doctest::Approx(0.056444));
  const test::Loaded bandai = test::load(test::shared_clip("dataset-1_walk_normal_001.bvh"));
  CHECK(bandai.conversion.geometry.metres_per_unit == doctest::Approx(0.01));
  // The same clip in metres and in inches.
  const motion::Clip in_m = scaled(bandai.clip, 0.01), in_inch = scaled(bandai.clip, 1.0 / 2.54);
  CHECK(convert_motion(in_m, map_skeleton(in_m), {}).geometry.metres_per_unit == doctest::Approx(1.0));
  CHECK(convert_motion(in_inch, map_skeleton(in_inch), {}).geometry.metres_per_unit == doctest::Approx(0.0254));
  // Same motion, same metres: the analysis does not depend on the file's unit.
  CHECK(zmp_outside_total(in_m) == doctest::Approx(zmp_outside_total(bandai.clip)).epsilon(1e-9));
  ConvertOptions given;
  given.metres_per_unit = 0.02;
  const Conversion forced = convert_motion(bandai.clip, bandai.mapping, given);
  CHECK_FALSE(forced.unit_guessed);
  CHECK(forced.geometry.metres_per_unit == 0.02);
  given.metres_per_unit = -1.0;
  CHECK_FALSE(convert_motion(bandai.clip, bandai.mapping, given).ok());
}

TEST_CASE("convert: a leading T-pose is detected and excluded, a normal first frame is not") {
  const test::Loaded cmu = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  CHECK(cmu.conversion.tpose_excluded);
  CHECK(cmu.conversion.motion.first_frame == 1);
  ConvertOptions keep;
  keep.exclude_tpose = false;
  CHECK(test::load(test::bundled_clip("cmu_02_walk.bvh"), keep).conversion.motion.first_frame == 0);
  for (const char* clip : {"dataset-1_walk_normal_001.bvh", "dataset-2_run_normal_010.bvh", "cmu_01_01_jumps.bvh"}) {
    const test::Loaded l = test::load(test::shared_clip(clip));
    INFO(clip);
    CHECK(l.conversion.motion.first_frame == (std::string(clip).rfind("cmu", 0) == 0 ? 1U : 0U));
  }
}

TEST_CASE("convert: conventions are recognised by their names, Mixamo prefixes are ignored") {
  CHECK(test::load(test::bundled_clip("cmu_02_walk.bvh")).mapping.map.convention.find("CMU") == 0);
  const test::Loaded bandai = test::load(test::shared_clip("dataset-1_walk_normal_001.bvh"));
  CHECK(bandai.mapping.map.convention.find("Bandai") == 0);
  // The CMU clip renamed the Mixamo way.
  motion::Clip mixamo = test::load(test::bundled_clip("cmu_02_walk.bvh")).clip;
  for (motion::Joint& j : mixamo.joints) {
    if (!j.end_site) j.name = "mixamorig:" + j.name;
  }
  const MapResult m = map_skeleton(mixamo);
  REQUIRE(m.ok());
  CHECK(zmp_outside_total(mixamo) ==
        doctest::Approx(zmp_outside_total(test::load(test::bundled_clip("cmu_02_walk.bvh")).clip)));
}

TEST_CASE("convert: a mapping file overrides names, malformed or missing mappings are refused with the line") {
  motion::Clip c = test::load(test::shared_clip("dataset-1_walk_normal_001.bvh")).clip;
  const std::size_t thigh = *motion::find_joint(c, "UpperLeg_L");
  c.joints[thigh].name = "weird_thigh_name";
  const MapResult missing = map_skeleton(c);
  CHECK_FALSE(missing.ok());
  CHECK(missing.error.find("LeftUpperLeg") != std::string::npos);
  const MapResult fixed = map_skeleton(c, "# my rig\nLeftUpperLeg = weird_thigh_name\n");
  REQUIRE(fixed.ok());
  CHECK(fixed.map.joint[tonus::sim::index(tonus::sim::Bone::LeftUpperLeg)] == static_cast<int>(thigh));
  CHECK(map_skeleton(c, "LeftUpperLeg weird_thigh_name").error.find("line 1") != std::string::npos);
  CHECK(map_skeleton(c, "\nLeftThigh = weird_thigh_name").error.find("line 2") != std::string::npos);
  CHECK(map_skeleton(c, "LeftUpperLeg = no_such_joint").error.find("no_such_joint") != std::string::npos);
}

TEST_CASE("convert: skeletons without toes get a sole from the ankle, the analysis still runs") {
  motion::Clip c = test::load(test::shared_clip("dataset-1_walk_normal_001.bvh")).clip;
  for (motion::Joint& j : c.joints) {
    if (j.name == "Toes_L" || j.name == "Toes_R") j.name += "_unmapped";
  }
  const MapResult m = map_skeleton(c);
  REQUIRE(m.ok());
  CHECK(m.map.joint[tonus::sim::index(tonus::sim::Bone::LeftToes)] == -1);
  const Conversion conv = convert_motion(c, m, {});
  REQUIRE(conv.ok());
  const Analysis a = analyse(conv.motion, AnalysisOptions{});
  REQUIRE(a.ok());
  CHECK(a.summary.frames == c.frame_count);
  CHECK(a.summary.frames_airborne < a.summary.frames / 4);  // the soles still find the ground
}

TEST_CASE("convert: the same motion written with another rotation order analyses the same") {
  // Rewrite every 3-rotation joint of the CMU clip (ZYX) in XZY order.
  const motion::Clip zyx = test::load(test::bundled_clip("cmu_02_walk.bvh")).clip;
  motion::Clip xzy = zyx;
  for (std::size_t j = 0; j < zyx.joints.size(); ++j) {
    auto& ch = xzy.joints[j].channels;
    if (!motion::rotation_order(zyx.joints[j])) continue;
    // Positions keep their place; the three rotation channels become X Z Y.
    std::size_t r = 0;
    const motion::Channel order[3] = {motion::Channel::x_rotation, motion::Channel::z_rotation,
                                      motion::Channel::y_rotation};
    for (motion::Channel& c : ch) {
      if (motion::is_rotation(c)) c = order[r++];
    }
  }
  for (std::size_t f = 0; f < zyx.frame_count; ++f) {
    for (std::size_t j = 0; j < zyx.joints.size(); ++j) {
      if (!motion::rotation_order(zyx.joints[j])) continue;
      const auto q = motion::local_rotation(zyx, f, j);
      REQUIRE(q);
      REQUIRE(motion::set_local_rotation(xzy, f, j, *q));
    }
  }
  CHECK(zmp_outside_total(xzy) == doctest::Approx(zmp_outside_total(zyx)).epsilon(1e-9));
}

TEST_CASE("convert: clips that cannot be analysed are refused clearly") {
  motion::Clip c = test::load(test::shared_clip("dataset-2_run_normal_010.bvh")).clip;
  // A single frame.
  motion::Clip one = c;
  one.frame_count = 1;
  one.values.resize(one.channel_count());
  CHECK(convert_motion(one, map_skeleton(one), {}).error.find("two frames") != std::string::npos);
  // Legs of zero length.
  motion::Clip flat = c;
  for (motion::Joint& j : flat.joints) j.offset.setZero();
  for (std::size_t f = 0; f < flat.frame_count; ++f) {
    for (std::size_t k = 0; k < flat.channel_count(); ++k) flat.frame(f)[k] = 0.0;
  }
  CHECK_FALSE(convert_motion(flat, map_skeleton(flat), {}).ok());
}
