// solve_ik allocates nothing: every malloc family call and operator new is
// counted (tests/support/allocation_counter) over 6,000 frames of 3- and
// 6-point tracking with steps, lost trackers, NaN and absurd samples mixed in.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "support/allocation_counter.hpp"
#include "tonus/host/reference/calibration.hpp"
#include "tonus/host/reference/tracker_ik.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;
using reference::Tracker;
using sim::Quat;
using sim::Vec3;

TEST_CASE("tracker IK: 6,000 solves allocate nothing") {
  REQUIRE(test::probe_allocation_counter() == 2);
  // A standing T-pose sample of a 1.70 m performer (hands at the wrists' height, arms out).
  reference::TrackerFrame standing;
  standing[Tracker::head] = {Vec3(0.08, 0.0, 0.936 * 1.70), Quat::Identity(), true};
  standing[Tracker::left_hand] = {Vec3(0.0, 0.87, 0.818 * 1.70), Quat::Identity(), true};
  standing[Tracker::right_hand] = {Vec3(0.0, -0.87, 0.818 * 1.70), Quat::Identity(), true};
  standing[Tracker::waist] = {Vec3(-0.1, 0.0, 0.53 * 1.70), Quat::Identity(), true};
  standing[Tracker::left_foot] = {Vec3(0.05, 0.09, 0.1), Quat::Identity(), true};
  standing[Tracker::right_foot] = {Vec3(0.05, -0.09, 0.1), Quat::Identity(), true};
  const reference::CalibrationResult cal = reference::calibrate(standing);
  REQUIRE_MESSAGE(cal.ok(), cal.error);
  const sim::BuildResult built = sim::build_humanoid(reference::calibrated_spec(cal.body, 65.0));
  REQUIRE(built);
  const reference::IkCreated ik = reference::make_ik_model(*built.model, cal.body);
  REQUIRE_MESSAGE(ik.model, ik.error);

  // The frames, made before counting: walking, turning, crouching, waving; every 11th broken, trackers lost.
  std::vector<reference::TrackerFrame> frames(3000);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const double t = static_cast<double>(f) / 90.0;
    const Quat yaw(Eigen::AngleAxisd(0.3 * t, Vec3::UnitZ()));
    const Vec3 base(0.8 * t, 0.2 * std::sin(t), -0.2 * (1.0 - std::cos(0.5 * t)));
    reference::TrackerFrame& s = frames[f];
    s = standing;
    s.time_s = t;
    for (reference::TrackerPose& p : s.pose) {
      p.pos_m = base + yaw * p.pos_m;
      p.rot = yaw;
    }
    s[Tracker::left_hand].pos_m += Vec3(0.3 * std::sin(3.0 * t), -0.4, -0.3);
    if (f % 11 == 3) s[Tracker::head].pos_m.x() = nan;
    if (f % 11 == 7) s[Tracker::right_hand].rot = Quat(0.0, 0.0, 0.0, 0.0);
    if (f % 500 > 400) s[Tracker::left_hand].valid = false;  // lost: held, eased, recovered
    if (f % 700 > 650) s[Tracker::waist].valid = false;
    if (f % 13 == 5) s[Tracker::left_foot].pos_m = Vec3(1e9, 0.0, 0.0);
  }
  reference::IkState state;
  reference::IkOutput out;
  for (const bool six : {false, true}) {
    reference::IkModel model = *ik.model;
    if (!six) {
      for (const Tracker t : {Tracker::waist, Tracker::left_foot, Tracker::right_foot}) {
        model.calibration.offset[reference::index(t)].valid = false;
      }
    }
    state = reference::IkState{};
    test::start_counting_allocations();
    for (const reference::TrackerFrame& f : frames) reference::solve_ik(model, state, f, out);
    const long allocations = test::stop_counting_allocations();
    CAPTURE(six);
    CHECK(allocations == 0);
    CHECK(state.stats.frames == frames.size());
    CHECK(state.stats.invalid_samples > 0);
    if (!six) CHECK(state.stats.steps > 10);
    for (int i = 0; i < out.nq; ++i) CHECK(std::isfinite(out.qpos[static_cast<std::size_t>(i)]));
  }
}
