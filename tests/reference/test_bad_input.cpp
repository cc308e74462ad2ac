// Bad input comes back as a clear error, never a crash or an exception; and
// the clip checks themselves catch a wrong answer.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "reference_checks.hpp"
#include "support/scratch_dir.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/model_builder.hpp"

using namespace tonus;
using reference::clip_to_reference;
using reference::ClipReference;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string p = test::scratch_path(name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("reference: a missing file, an empty clip and garbage are refused with their reason") {
  const sim::Model& m = reference::test::humanoid();
  const ClipReference missing = clip_to_reference(m, std::string("/nonexistent/clip.bvh"));
  CHECK_FALSE(missing.ok());
  CHECK(contains(missing.error, "/nonexistent/clip.bvh"));
  CHECK(missing.qpos.empty());

  const std::string empty_path = write_temp("tonus_reference_empty.bvh", "");
  const ClipReference empty = clip_to_reference(m, empty_path);
  CHECK_FALSE(empty.ok());
  CHECK(contains(empty.error, empty_path));

  const std::string no_frames = write_temp("tonus_reference_no_frames.bvh",
                                           "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition "
                                           "Zposition\n  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: 0\n"
                                           "Frame Time: 0.01\n");
  const ClipReference zero = clip_to_reference(m, no_frames);
  CHECK_FALSE(zero.ok());
  MESSAGE("no frames: " << zero.error);

  const std::string garbage = write_temp("tonus_reference_garbage.bvh", std::string("\x01\xff{}MOTION\0junk", 15));
  CHECK_FALSE(clip_to_reference(m, garbage).ok());

  const ClipReference none = clip_to_reference(m, balance::HumanMotion{});
  CHECK_FALSE(none.ok());
  CHECK(contains(none.error, "no frames"));
}

TEST_CASE("reference: a skeleton that cannot be mapped names the missing bone") {
  const std::string path = write_temp("tonus_reference_unmapped.bvh",
                                      "HIERARCHY\nROOT Base\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition "
                                      "Zposition Zrotation Xrotation Yrotation\n  JOINT Arm\n  {\n    OFFSET 0 10 0\n"
                                      "    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n"
                                      "      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: 2\nFrame Time: 0.01\n"
                                      "0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0\n");
  const ClipReference r = clip_to_reference(reference::test::humanoid(), path);
  CHECK_FALSE(r.ok());
  CHECK(contains(r.error, "no joint for"));
  MESSAGE("unmapped: " << r.error);
}

TEST_CASE("reference: a model that is not the humanoid, or a motion with broken numbers, is refused") {
  const balance::Conversion conv = reference::test::load(reference::test::bundled_clip("cmu_02_walk.bvh"));
  sim::ModelBuilder mb;
  sim::BodySpec b;
  b.name = "Hips";
  b.joint = sim::JointType::free;
  b.mass_kg = 1.0;
  b.inertia = sim::Mat3::Identity() * 0.01;
  mb.add_body(b);
  const sim::BuildResult one = mb.build();
  REQUIRE_MESSAGE(one, one.error);
  const ClipReference wrong_model = clip_to_reference(*one.model, conv.motion);
  CHECK_FALSE(wrong_model.ok());
  CHECK(contains(wrong_model.error, "not the humanoid"));

  balance::HumanMotion broken = conv.motion;
  broken.frames[10].p[3].x() = std::numeric_limits<double>::quiet_NaN();
  const ClipReference nan = clip_to_reference(reference::test::humanoid(), broken);
  CHECK_FALSE(nan.ok());
  CHECK(contains(nan.error, "frame 10"));

  balance::HumanMotion no_time = conv.motion;
  no_time.dt_s = 0.0;
  CHECK_FALSE(clip_to_reference(reference::test::humanoid(), no_time).ok());

  balance::HumanMotion one_frame = conv.motion;
  one_frame.frames.resize(1);
  one_frame.first_frame = 0;
  const ClipReference single = clip_to_reference(reference::test::humanoid(), one_frame);
  CHECK_MESSAGE(single.ok(), single.error);
  CHECK(single.qpos.size() == 1);
}

TEST_CASE("reference: the path and the motion give the same configurations, and other heights scale") {
  const std::string path = reference::test::bundled_clip("cmu_02_walk.bvh");
  const balance::Conversion conv = reference::test::load(path);
  const ClipReference a = clip_to_reference(reference::test::humanoid(), conv.motion);
  const ClipReference b = clip_to_reference(reference::test::humanoid(), path);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(a.qpos.size() == b.qpos.size());
  CHECK(a.qpos.back() == b.qpos.back());
  CHECK(b.messages.size() > a.messages.size());  // the conversion's notes come first

  sim::HumanoidSpec small;
  small.height_m = 1.50;
  const sim::BuildResult built = sim::build_humanoid(small);
  REQUIRE_MESSAGE(built, built.error);
  const ClipReference s = clip_to_reference(*built.model, conv.motion);
  REQUIRE_MESSAGE(s.ok(), s.error);
  CHECK(s.scale == doctest::Approx(a.scale * 1.50 / 1.70).epsilon(1e-9));
  const reference::test::Figures fig = reference::test::evaluate(*built.model, conv.motion, s);
  CHECK(fig.all_deg.p95 < 1.0);
  CHECK(fig.contact_foot_z_m.p95 < 0.04);
}

TEST_CASE("reference: the checks catch a wrong answer (a tilted, shifted root, a straightened elbow)") {
  const balance::Conversion conv = reference::test::load(reference::test::bundled_clip("cmu_02_walk.bvh"));
  const sim::Model& m = reference::test::humanoid();
  ClipReference r = clip_to_reference(m, conv.motion);
  REQUIRE(r.ok());
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()));
  for (auto& q : r.qpos) {
    const Eigen::Quaterniond root = tilt * Eigen::Quaterniond(q[3], q[4], q[5], q[6]);
    q[3] = root.w();
    q[4] = root.x();
    q[5] = root.y();
    q[6] = root.z();
    q[0] += 0.05;
    q[static_cast<std::size_t>(m.bodies[sim::index(sim::Bone::LeftLowerArm)].qpos_adr)] = 0.0;
  }
  const reference::test::Figures fig = reference::test::evaluate(m, conv.motion, r);
  CHECK(fig.all_deg.median > 5.0);
  CHECK(fig.segment_deg[1].median > 10.0);
  CHECK(fig.root_path_error_m > 0.01);
}
