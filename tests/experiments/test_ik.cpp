// The tracker IK on real walks (tools/tonus/experiments/ik_eval.hpp): the
// issue's goals, the trackers synthesized from sim's kinematics of the clip
// retargeted onto a humanoid, the solution judged by sim's kinematics too.
#include <doctest/doctest.h>

#include <array>
#include <filesystem>

#include "experiments/ik_eval.hpp"
#include "support/sanitized.hpp"

namespace tonus::experiments {
namespace {

std::vector<std::string> walks() {
  std::vector<std::string> clips{std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh"};
  const std::string bandai = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_walk_normal_001.bvh";
  if (std::filesystem::exists(bandai)) clips.push_back(bandai);
  return clips;
}

TEST_CASE("tonus ik: walks from 3 and 6 trackers meet the goals") {
  for (const std::string& clip : walks()) {
    for (const int trackers : {3, 6}) {
      CAPTURE(clip);
      CAPTURE(trackers);
      IkEvalOptions opt;
      opt.clip = clip;
      opt.trackers = trackers;
      const IkEvalResult r = run_ik_eval(opt);
      REQUIRE_MESSAGE(r.error.empty(), r.error);
      REQUIRE(r.runs.size() == 4);
      const IkRun& clean = r.runs[0];
      MESSAGE(clip << " " << trackers << " trackers: MPJPE " << clean.mpjpe_cm << " cm (upper " << clean.mpjpe_upper_cm
                   << ", lower " << clean.mpjpe_lower_cm << "), wrists within 1 mm " << clean.hand_within_1mm_share
                   << ", jitter x" << clean.jitter_ratio << "; noise " << r.runs[1].mpjpe_cm << " cm, dropouts "
                   << r.runs[2].mpjpe_cm << " cm");
      // The calibration recovers the clip's stature from its T-pose.
      CHECK(r.calibrated_height_m == doctest::Approx(r.truth_height_m).epsilon(0.01));
      // 3 points: half of Final IK's 18.1 cm; 6 points: 3 cm.
      CHECK(clean.mpjpe_cm <= (trackers == 3 ? 9.0 : 3.0));
      // The head is always placed (3 points) or reached within 1.5 mm (6: the spine's ranges).
      CHECK(clean.head_error_max_mm <= (trackers == 3 ? 1e-3 : 1.5));
      CHECK(clean.hand_within_1mm_share >= 0.8);
      CHECK(clean.hand_error_max_reached_mm <= 1.0);
      // Noise and dropouts cost something, and nothing breaks.
      CHECK(r.runs[1].mpjpe_cm < clean.mpjpe_cm + 2.0);
      CHECK(r.runs[2].mpjpe_cm < 3.0 * clean.mpjpe_cm + 10.0);
      // The input filter takes most of the noise's jitter out.
      CHECK(r.runs[3].jitter_ratio < 0.5 * r.runs[1].jitter_ratio);
      // Jitter no higher than the clip's, with a ceiling just above today's
      // figures: 3 points 0.74 and 0.87 since the procedural swings land at
      // rest (0.81 and 1.03 before); 6 points 0.97 and 0.97 since the neck
      // joint keeps behind the spine-to-head line (1.047 and 1.031 before:
      // it swung across the line with the head's sway, shaking the neck,
      // shoulders and arms).
      const bool cmu = clip.find("cmu_02_walk") != std::string::npos;
      CHECK(clean.jitter_ratio <= (trackers == 6 ? 0.99 : (cmu ? 0.78 : 0.9)));
    }
  }
}

TEST_CASE("tonus ik: no jerkier than the clip on every shared clip but the kicks from 6 points" *
          tonus::test::heavy_under_sanitizers()) {
  // The goal, jitter no higher than the source's, on the shared
  // clips from 3 and 6 trackers (docs/reference.md). Met on 13 runs of 14
  // since the procedural swings land at rest where the pelvis will need them
  // (3-point walks 0.81 and 1.03 before, run 1.035), a planted foot pivots
  // under a spinning body (kicks 1.40 -> 1.16) and the 6-point neck joint
  // keeps behind the spine-to-head line (walks 1.047 and 1.031 before). The
  // kicks from 3 points but not from 6 (0.983 and 1.049 since the 6-point
  // chest's turn from the waist was bounded, the knee pole carried with the
  // leg's turn, the chest twist led by a flung hand and the 6-point heading
  // smoothed over 100 ms; 0.9993 and 1.088 before, 1.149 and 1.152 before the
  // thigh's range rescue, the clavicle lowering over 70 ms, the heading's two
  // stages, a hand too near the shoulder turning the clavicle away and the
  // chest twisting toward a hand beyond reach: the elbows straightening and
  // the hand missed under a chest turned 10-35 degrees from the performer's
  // at the spins' starts, docs/reference.md), so a ceiling just above keeps
  // them from growing. The run's MPJPE too: its 6-point knees
  // (pole smoothed over 150 ms) once made it the worst 6-point run.
  struct Clip {
    const char* file;
    std::array<double, 2> ceiling;  // 3, 6 trackers
  };
  // (The walks: the test above.)
  const std::array<Clip, 5> clips{{{"cmu_01_01_jumps.bvh", {1.0, 1.0}},
                                   {"dataset-2_run_normal_010.bvh", {1.0, 1.0}},
                                   {"dataset-1_kick_normal_001.bvh", {1.0, 1.055}},
                                   {"dataset-1_punch_normal_001.bvh", {1.0, 1.0}},
                                   {"dataset-2_wave-both-hands_normal_001.bvh", {1.0, 1.0}}}};
  for (const Clip& c : clips) {
    const std::string path = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/" + c.file;
    if (!std::filesystem::exists(path)) {
      MESSAGE("no shared clip " << c.file << ": skipped");
      continue;
    }
    for (const int trackers : {3, 6}) {
      CAPTURE(c.file);
      CAPTURE(trackers);
      IkEvalOptions opt;
      opt.clip = path;
      opt.trackers = trackers;
      const IkEvalResult r = run_ik_eval(opt);
      REQUIRE_MESSAGE(r.error.empty(), r.error);
      const IkRun& clean = r.runs.at(0);
      MESSAGE(std::string(c.file) << ", " << trackers << " trackers: MPJPE " << clean.mpjpe_cm << " cm, jitter x"
                                  << clean.jitter_ratio);
      CHECK(clean.jitter_ratio <= c.ceiling[trackers == 3 ? 0 : 1]);
      CHECK(clean.hand_error_max_reached_mm <= 1.0);
      if (std::string(c.file).find("run") != std::string::npos) {
        CHECK(clean.mpjpe_cm <= (trackers == 3 ? 10.5 : 3.0));
      }
    }
  }
}

}  // namespace
}  // namespace tonus::experiments
