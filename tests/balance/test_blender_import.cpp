// The BVH files tonus reads and writes, read by a reader that is not ours:
// Blender's own importer (io_anim_bvh, Debian's blender), run headless by
// blender_bvh_dump.py, which writes every bone's head at every frame. Checks
// that our reader's forward kinematics agrees with Blender's on every shared
// clip, and that the balance filter's written clips import in Blender with
// every joint where we put it and the feet that carry weight where the
// capture had them (issue 14: "the written BVH still imports in Blender").
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "balance_fixtures.hpp"
#include "support/read_file.hpp"
#include "support/sanitized.hpp"
#include "support/scratch_dir.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/balance/robust_filter.hpp"
#include "tonus/host/motion/kinematics.hpp"

namespace tonus::balance {
namespace {

// Every bone's head per frame, in the file's axes and units, as Blender placed it.
struct BlenderImport {
  std::string version;
  std::size_t frames = 0;
  std::map<std::string, std::vector<Eigen::Vector3d>> heads;
  std::string error;
};

BlenderImport import_in_blender(const std::string& bvh_path, const std::string& tag) {
  BlenderImport b;
  const std::string json_path = tonus::test::scratch_path(tag + ".json"),
                    log_path = tonus::test::scratch_path(tag + ".log");
  const std::string cmd = std::string("'") + TONUS_BLENDER + "' -b --factory-startup --python-exit-code 1 --python '" +
                          TONUS_BLENDER_SCRIPT + "' -- '" + bvh_path + "' '" + json_path + "' > '" + log_path +
                          "' 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    b.error = "blender failed: " + cmd + "\n" + tonus::test::read_file(log_path);
    return b;
  }
  const nlohmann::json j = nlohmann::json::parse(tonus::test::read_file(json_path), nullptr, false);
  if (j.is_discarded()) {
    b.error = "unreadable JSON from blender: " + json_path;
    return b;
  }
  b.version = j.at("blender").get<std::string>();
  b.frames = j.at("frames").get<std::size_t>();
  for (const auto& [name, flat] : j.at("bones").items()) {
    std::vector<Eigen::Vector3d>& h = b.heads[name];
    for (std::size_t i = 0; i + 2 < flat.size(); i += 3) h.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  }
  return b;
}

struct Agreement {
  std::size_t bones_compared = 0;
  std::size_t bones_missing = 0;  // joints (not End Sites) Blender has no bone for
  double max_error = 0.0;         // file units
  std::string worst;
};

// Blender's heads against our forward kinematics of the same file, every
// joint that is not an End Site, every frame.
Agreement compare(const motion::Clip& clip, const BlenderImport& b) {
  Agreement a;
  std::vector<std::pair<std::size_t, const std::vector<Eigen::Vector3d>*>> matched;  // joint, Blender's heads
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    if (clip.joints[j].end_site) continue;
    const auto it = b.heads.find(clip.joints[j].name);
    if (it == b.heads.end() || it->second.size() != clip.frame_count) {
      ++a.bones_missing;
      continue;
    }
    matched.emplace_back(j, &it->second);
  }
  a.bones_compared = matched.size();
  std::vector<motion::JointPose> poses;
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    if (!motion::forward_kinematics(clip, f, poses)) {
      a.max_error = std::numeric_limits<double>::infinity();
      a.worst = "no forward kinematics at frame " + std::to_string(f);
      break;
    }
    for (const auto& [j, heads] : matched) {
      const double e = ((*heads)[f] - poses[j].position).norm();
      if (e > a.max_error) {
        a.max_error = e;
        a.worst = clip.joints[j].name + " at frame " + std::to_string(f);
      }
    }
  }
  return a;
}

// A clip's size in its own units: the largest extent of its joints at frame 0.
double extent(const motion::Clip& clip) {
  const std::vector<motion::JointPose> p = motion::forward_kinematics(clip, 0);
  Eigen::Vector3d lo = p.front().position, hi = lo;
  for (const motion::JointPose& q : p) {
    lo = lo.cwiseMin(q.position);
    hi = hi.cwiseMax(q.position);
  }
  return (hi - lo).maxCoeff();
}

TEST_CASE("Blender's BVH importer puts every joint of every shared clip where our reader does") {
  const std::vector<std::string> paths = {
      test::bundled_clip("cmu_02_walk.bvh"),
      test::shared_clip("cmu_01_01_jumps.bvh"),
      test::shared_clip("dataset-1_walk_normal_001.bvh"),
      test::shared_clip("dataset-2_run_normal_010.bvh"),
      test::shared_clip("dataset-1_kick_normal_001.bvh"),
      test::shared_clip("dataset-1_punch_normal_001.bvh"),
      test::shared_clip("dataset-2_wave-both-hands_normal_001.bvh"),
  };
  int n = 0;
  for (const std::string& path : paths) {
    CAPTURE(path);
    const motion::ReadResult ours = motion::read_bvh_file(path);
    REQUIRE_MESSAGE(ours.ok(), (ours.error ? ours.error->message : std::string()));
    const BlenderImport b = import_in_blender(path, "original" + std::to_string(n++));
    REQUIRE_MESSAGE(b.error.empty(), b.error);
    CHECK(b.frames == ours.clip.frame_count);
    const Agreement a = compare(ours.clip, b);
    const double size = extent(ours.clip);
    MESSAGE(path << ": Blender " << b.version << ", " << a.bones_compared << " bones, " << b.frames
                 << " frames, largest difference " << a.max_error << " units (" << a.max_error / size
                 << " of the joints' extent at frame 0), " << a.worst);
    CHECK(a.bones_missing == 0);
    CHECK(a.bones_compared == b.heads.size());
    // Blender keeps single-precision floats: a few parts in 10^7 of the
    // coordinates, which run to several metres from the origin.
    CHECK(a.max_error < 4e-6 * size);
  }
}

void check_written(const std::string& name, const std::string& path) {
  const test::Loaded l = test::load(path);
  const RobustFilterResult r = robust_balance_filter(l.conversion.motion, {});
  REQUIRE_MESSAGE(r.ok(), r.error);
  const AppliedCorrection applied = apply_correction(l.clip, l.conversion.geometry, l.conversion.motion, r.rotation,
                                                     r.shift_m, r.follow, r.drop_m, r.arm_swing_rad);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  const std::string written = tonus::test::scratch_path(name + ".bvh");
  {
    std::ofstream out(written);
    out << motion::write_bvh(applied.clip, 6);
    REQUIRE(out.good());
  }
  const motion::ReadResult back = motion::read_bvh_file(written);
  REQUIRE_MESSAGE(back.ok(), (back.error ? back.error->message : std::string()));
  const BlenderImport before = import_in_blender(path, name + "-original");
  const BlenderImport after = import_in_blender(written, name + "-written");
  REQUIRE_MESSAGE(before.error.empty(), before.error);
  REQUIRE_MESSAGE(after.error.empty(), after.error);
  CHECK(after.frames == l.clip.frame_count);

  // Every joint where our reader puts it.
  const Agreement a = compare(back.clip, after);
  const double size = extent(back.clip), unit_m = l.conversion.geometry.metres_per_unit;
  CHECK(a.bones_missing == 0);
  CHECK(a.max_error < 4e-6 * size);

  // The feet that are down, as Blender reads the two files: their ankle and
  // toe joints stay put to within Blender's float precision, and the edit
  // is real (the hips moved).
  const ContactTrack contacts = detect_contacts(l.conversion.motion, {});
  const SkeletonMap& map = l.conversion.geometry.map;
  double feet_moved_m = 0.0, hips_moved_m = 0.0;
  std::size_t foot_frames = 0;
  const std::string hips = l.clip.joints[static_cast<std::size_t>(map.joint[sim::index(sim::Bone::Hips)])].name;
  for (std::size_t f = l.conversion.motion.first_frame; f < l.clip.frame_count; ++f) {
    hips_moved_m = std::max(hips_moved_m, unit_m * (after.heads.at(hips)[f] - before.heads.at(hips)[f]).norm());
    for (int foot = 0; foot < 2; ++foot) {
      if (!contacts.frames[f][static_cast<std::size_t>(foot)].any()) continue;
      ++foot_frames;
      const sim::Bone bones[2] = {foot == 0 ? sim::Bone::LeftFoot : sim::Bone::RightFoot,
                                  foot == 0 ? sim::Bone::LeftToes : sim::Bone::RightToes};
      for (const sim::Bone bone : bones) {
        const int j = map.joint[sim::index(bone)];
        if (j < 0) continue;
        const std::string& joint = l.clip.joints[static_cast<std::size_t>(j)].name;
        feet_moved_m = std::max(feet_moved_m, unit_m * (after.heads.at(joint)[f] - before.heads.at(joint)[f]).norm());
      }
    }
  }
  MESSAGE(name << ": written clip in Blender: largest difference from our reader " << a.max_error
               << " units; feet down (" << foot_frames << " foot-frames) moved by at most " << 1000.0 * feet_moved_m
               << " mm, the hips by up to " << 100.0 * hips_moved_m << " cm");
  CHECK(foot_frames > 0);
  CHECK(feet_moved_m < 1e-4);
  CHECK(hips_moved_m > 0.01);
}

TEST_CASE("the robust balance filter's written CMU walk imports in Blender, the feet down where they were" *
          tonus::test::heavy_under_sanitizers()) {
  check_written("cmu-walk", test::bundled_clip("cmu_02_walk.bvh"));
}

TEST_CASE("the robust balance filter's written Bandai Namco kicks import in Blender, the feet down where they were" *
          tonus::test::heavy_under_sanitizers()) {
  check_written("bandai-kicks", test::shared_clip("dataset-1_kick_normal_001.bvh"));
}

}  // namespace
}  // namespace tonus::balance
