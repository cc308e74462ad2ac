#include "ik_eval.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "stats.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/skeleton_map.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/reference/calibration.hpp"
#include "tonus/host/reference/clip_reference.hpp"
#include "tonus/host/reference/tracker_ik.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::experiments {
namespace {

using reference::Tracker;
using reference::TrackerFrame;
using reference::TrackerPose;
using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr double kMassKg = 65.0;
constexpr double kReferenceHeight_m = 1.70;

bool is_lower(std::size_t bone) { return bone == sim::index(Bone::Hips) || (bone >= sim::index(Bone::LeftUpperLeg)); }

// Where each tracker sits on its bone (bone frame): a headset in front of the
// eyes and pitched, controllers in the palms and turned, a belt tracker at
// the back, foot trackers on the instep. Any such offsets would do: the
// calibration measures them.
std::array<TrackerPose, reference::kTrackerCount> worn_offsets(double height_m) {
  std::array<TrackerPose, reference::kTrackerCount> o{};
  const auto set = [&](Tracker t, const Vec3& p, const Quat& q) { o[reference::index(t)] = {p, q, true}; };
  const auto turn = [](double a, const Vec3& axis) { return Quat(Eigen::AngleAxisd(a, axis)); };
  const double s = height_m / kReferenceHeight_m;
  set(Tracker::head, Vec3(0.09, 0.0, 0.08) * s, turn(0.17, Vec3::UnitY()));
  set(Tracker::left_hand, Vec3(0.0, 0.043 * height_m, -0.02), turn(0.5, Vec3::UnitX()));
  set(Tracker::right_hand, Vec3(0.0, -0.043 * height_m, -0.02), turn(-0.5, Vec3::UnitX()));
  set(Tracker::waist, Vec3(-0.10, 0.0, 0.02) * s, Quat::Identity());
  set(Tracker::left_foot, Vec3(0.05, 0.0, 0.04) * s, turn(0.3, Vec3::UnitY()));
  set(Tracker::right_foot, Vec3(0.05, 0.0, 0.04) * s, turn(0.3, Vec3::UnitY()));
  return o;
}

std::array<bool, reference::kTrackerCount> worn_set(int trackers) {
  std::array<bool, reference::kTrackerCount> w{};
  w[reference::index(Tracker::head)] = w[reference::index(Tracker::left_hand)] =
      w[reference::index(Tracker::right_hand)] = true;
  if (trackers == 6) {
    w[reference::index(Tracker::waist)] = w[reference::index(Tracker::left_foot)] =
        w[reference::index(Tracker::right_foot)] = true;
  }
  return w;
}

// The trackers the posed humanoid in `data` carries.
TrackerFrame trackers_of(const sim::Data& data, const std::array<TrackerPose, reference::kTrackerCount>& offsets,
                         const std::array<bool, reference::kTrackerCount>& worn) {
  TrackerFrame f;
  for (std::size_t t = 0; t < reference::kTrackerCount; ++t) {
    if (!worn[t]) continue;
    const std::size_t b = sim::index(reference::tracked_bone(static_cast<Tracker>(t)));
    const TrackerPose bone{data.xbody[b].pos, data.xquat[b], true};
    f.pose[t] = reference::compose(bone, offsets[t]);
  }
  return f;
}

// Per joint, the sum over the track of the jerk's size times dt^3 (the
// third difference of its position).
JointJerk jerk_sums(const std::vector<std::array<Vec3, sim::kBoneCount>>& j) {
  JointJerk sums{};
  for (std::size_t f = 3; f < j.size(); ++f) {
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      sums[b] += (j[f][b] - 3.0 * j[f - 1][b] + 3.0 * j[f - 2][b] - j[f - 3][b]).norm();
    }
  }
  return sums;
}

// Mean joint jerk (m/s^3) of a track of `frames` frames from its sums.
double jitter(const JointJerk& sums, std::size_t frames, double dt) {
  if (frames < 4) return 0.0;
  double total = 0.0;
  for (const double s : sums) total += s;
  return total / static_cast<double>((frames - 3) * sim::kBoneCount) / (dt * dt * dt);
}

IkRun run_condition(const std::string& condition, const IkSetup& truth, const reference::IkModel& ik,
                    const sim::Model& solved_model, const IkEvalOptions& opt) {
  IkRun run;
  run.condition = condition;
  const std::size_t n = truth.joints.size();
  run.frames = n;
  std::mt19937 rng(opt.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  // Dropouts: each tracker's gaps start at random, one gap of dropout_length_s per
  // dropout_length_s / dropout_share on average.
  const double gap_rate = opt.dropout_share / std::max(opt.dropout_length_s, 1e-3);  // gaps per second
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::array<double, reference::kTrackerCount> lost_until{};
  lost_until.fill(-1.0);

  auto state = std::make_unique<reference::IkState>();
  reference::IkOutput out;
  auto data = sim::make_data(solved_model);
  std::vector<std::array<Vec3, sim::kBoneCount>> solved(n);
  std::vector<double> times_us, all_err, up_err, low_err, hand_err, hand_reached, head_err, hand_truth;
  times_us.reserve(n);
  for (std::size_t f = 0; f < n; ++f) {
    TrackerFrame frame = truth.trackers[f];
    frame.time_s = static_cast<double>(f) * truth.dt_s;
    for (std::size_t t = 0; t < reference::kTrackerCount; ++t) {
      TrackerPose& p = frame.pose[t];
      if (!p.valid) continue;
      if (condition == "noise") {
        p.pos_m += opt.noise_pos_m * Vec3(gauss(rng), gauss(rng), gauss(rng));
        const Vec3 w = opt.noise_rot_rad * Vec3(gauss(rng), gauss(rng), gauss(rng));
        p.rot = (p.rot * sim::quat_exp(w)).normalized();
      } else if (condition == "dropouts") {
        if (frame.time_s >= lost_until[t] && uni(rng) < gap_rate * truth.dt_s) {
          lost_until[t] = frame.time_s + opt.dropout_length_s;
        }
        if (frame.time_s < lost_until[t]) p.valid = false;
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    reference::solve_ik(ik, *state, frame, out);
    const auto t1 = std::chrono::steady_clock::now();
    times_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    if (out.flags & (reference::kIkImplausible | reference::kIkHandsSwapped | reference::kIkNoHead)) {
      ++run.flagged_frames;
    }
    if (out.flags & reference::kIkHandUnreachable) ++run.unreachable_frames;
    if (out.flags & reference::kIkFootUnreachable) ++run.foot_unreachable_frames;

    // The solution through sim's kinematics, not the solver's own.
    data->qpos = out.qpos;
    sim::forward_kinematics(solved_model, *data);
    double sum = 0.0, sum_up = 0.0, sum_low = 0.0;
    int n_up = 0, n_low = 0;
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      solved[f][b] = data->xbody[b].pos;
      const double e = (solved[f][b] - truth.joints[f][b]).norm();
      run.joint_error_cm[b] += 100.0 * e / static_cast<double>(n);
      sum += e;
      (is_lower(b) ? sum_low : sum_up) += e;
      ++(is_lower(b) ? n_low : n_up);
    }
    all_err.push_back(100.0 * sum / static_cast<double>(sim::kBoneCount));
    up_err.push_back(100.0 * sum_up / n_up);
    low_err.push_back(100.0 * sum_low / n_low);
    // Hands and head against where their (possibly noisy) trackers put them.
    double worst_hand = 0.0;
    for (const Tracker t : {Tracker::left_hand, Tracker::right_hand}) {
      const TrackerPose& p = frame[t];
      const std::size_t b = sim::index(reference::tracked_bone(t));
      if (!p.valid || out.use[reference::index(t)] != reference::TrackerUse::live) continue;
      const TrackerPose bone = reference::compose(p, reference::inverse(ik.calibration.offset[reference::index(t)]));
      const double e = 1e3 * (data->xbody[b].pos - bone.pos_m).norm();
      hand_err.push_back(e);
      if (!(out.flags & reference::kIkHandUnreachable)) hand_reached.push_back(e);
      worst_hand = std::max(worst_hand, e);
      hand_truth.push_back(1e3 * (data->xbody[b].pos - truth.joints[f][b]).norm());
    }
    if (frame[Tracker::head].valid && out.use[reference::index(Tracker::head)] == reference::TrackerUse::live) {
      const TrackerPose bone = reference::compose(
          frame[Tracker::head], reference::inverse(ik.calibration.offset[reference::index(Tracker::head)]));
      head_err.push_back(1e3 * (data->xbody[sim::index(Bone::Head)].pos - bone.pos_m).norm());
    }
    run.frame_mpjpe_cm.push_back(all_err.back());
    run.frame_hand_mm.push_back(worst_hand);
    run.ankle_x_truth_m.push_back(truth.joints[f][sim::index(Bone::LeftFoot)].x());
    run.ankle_x_solved_m.push_back(solved[f][sim::index(Bone::LeftFoot)].x());
  }
  const auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (const double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  };
  const auto max_of = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  run.mpjpe_cm = mean(all_err);
  run.mpjpe_upper_cm = mean(up_err);
  run.mpjpe_lower_cm = mean(low_err);
  run.mpjpe_p95_cm = percentile(all_err, 0.95);
  run.mpjpe_max_cm = max_of(all_err);
  run.hand_error_mean_mm = mean(hand_err);
  run.hand_error_max_mm = max_of(hand_err);
  run.hand_error_p95_mm = percentile(hand_err, 0.95);
  run.hand_error_max_reached_mm = max_of(hand_reached);
  run.hand_within_1mm_share =
      hand_err.empty()
          ? 0.0
          : static_cast<double>(std::count_if(hand_err.begin(), hand_err.end(), [](double e) { return e <= 1.0; })) /
                static_cast<double>(hand_err.size());
  run.head_error_mean_mm = mean(head_err);
  run.head_error_max_mm = max_of(head_err);
  run.hand_truth_mean_mm = mean(hand_truth);
  const JointJerk solved_jerk = jerk_sums(solved);
  run.jitter_mps3 = jitter(solved_jerk, n, truth.dt_s);
  double truth_total = 0.0;
  for (const double j : truth.jerk) truth_total += j;
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    run.joint_jitter_ratio[b] = truth.jerk[b] > 0.0 ? solved_jerk[b] / truth.jerk[b] : 0.0;
    // Which joints the excess comes from: the shares add up to jitter_ratio - 1.
    run.joint_jitter_excess[b] = truth_total > 0.0 ? (solved_jerk[b] - truth.jerk[b]) / truth_total : 0.0;
  }
  const double source = jitter(truth.jerk, n, truth.dt_s);
  run.jitter_ratio = source > 0.0 ? run.jitter_mps3 / source : 0.0;
  double verr = 0.0;
  std::size_t nv = 0;
  for (std::size_t f = 1; f < n; ++f) {
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      verr += ((solved[f][b] - solved[f - 1][b]) - (truth.joints[f][b] - truth.joints[f - 1][b])).norm() / truth.dt_s;
      ++nv;
    }
  }
  run.velocity_error_mps = nv > 0 ? verr / static_cast<double>(nv) : 0.0;
  run.steps = state->stats.steps;
  run.clamped_frames = state->stats.clamped_frames;
  run.solve_mean_us = mean(times_us);
  run.solve_p99_us = percentile(times_us, 0.99);
  run.solve_max_us = max_of(times_us);
  return run;
}

}  // namespace

IkSetup prepare_ik_eval(const IkEvalOptions& opt, IkEvalResult& r) {
  IkSetup truth;
  r.clip = opt.clip;
  r.trackers = opt.trackers;
  if (opt.trackers != 3 && opt.trackers != 6) {
    r.error = "--trackers must be 3 (head, hands) or 6 (+ waist, feet)";
    return truth;
  }
  try {
    const motion::ReadResult read = motion::read_bvh_file(opt.clip);
    if (!read.ok()) {
      r.error = opt.clip + (read.error->line > 0 ? ":" + std::to_string(read.error->line) : std::string()) + ": " +
                read.error->message;
      return truth;
    }
    const balance::MapResult mapping = balance::map_skeleton(read.clip, opt.mapping_text);
    if (!mapping.ok()) {
      r.error = opt.clip + ": cannot map the skeleton onto the humanoid: " + mapping.error;
      return truth;
    }
    r.convention = mapping.map.convention;
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      const int j = mapping.map.joint[b];
      r.mapping.emplace_back(std::string(sim::kBones[b].name),
                             j >= 0 ? read.clip.joints[static_cast<std::size_t>(j)].name : std::string());
    }
    const balance::Conversion conv = balance::convert_motion(read.clip, mapping, balance::ConvertOptions{});
    if (!conv.ok()) {
      r.error = opt.clip + ": " + conv.error;
      return truth;
    }
    // The clip's stature: its legs against a reference humanoid's.
    sim::BuildResult ref_model = sim::build_humanoid(sim::HumanoidSpec{});
    if (!ref_model) {
      r.error = ref_model.error;
      return truth;
    }
    const reference::ClipReference scaled = reference::clip_to_reference(*ref_model.model, conv.motion);
    if (!scaled.ok()) {
      r.error = opt.clip + ": " + scaled.error;
      return truth;
    }
    r.truth_height_m = std::clamp(kReferenceHeight_m / scaled.scale, 1.2, 2.2);
    sim::HumanoidSpec truth_spec;
    truth_spec.height_m = r.truth_height_m;
    truth_spec.mass_kg = kMassKg;
    sim::BuildResult truth_model = sim::build_humanoid(truth_spec);
    if (!truth_model) {
      r.error = truth_model.error;
      return truth;
    }
    const reference::ClipReference clip = reference::clip_to_reference(*truth_model.model, conv.motion);
    if (!clip.ok()) {
      r.error = opt.clip + ": " + clip.error;
      return truth;
    }
    r.messages = clip.messages;
    r.frame_time_s = clip.dt_s;

    // The ground truth: joints and trackers from sim's kinematics.
    truth.model = std::move(truth_model.model);
    truth.dt_s = clip.dt_s;
    const auto offsets = worn_offsets(r.truth_height_m);
    const auto worn = worn_set(opt.trackers);
    auto data = sim::make_data(*truth.model);
    std::size_t last = clip.qpos.size();
    if (opt.max_seconds > 0.0) {
      last = std::min(last, clip.first_frame + static_cast<std::size_t>(opt.max_seconds / clip.dt_s));
    }
    for (std::size_t f = clip.first_frame; f < last; ++f) {
      data->qpos = clip.qpos[f];
      sim::forward_kinematics(*truth.model, *data);
      std::array<Vec3, sim::kBoneCount> j{};
      for (std::size_t b = 0; b < sim::kBoneCount; ++b) j[b] = data->xbody[b].pos;
      truth.joints.push_back(j);
      truth.trackers.push_back(trackers_of(*data, offsets, worn));
    }
    if (truth.joints.size() < 4) {
      r.error = opt.clip + ": too few frames to evaluate";
      return truth;
    }
    // Calibration: the performer stands in a T-pose first.
    data->qpos = truth.model->qpos0;
    sim::forward_kinematics(*truth.model, *data);
    const reference::CalibrationResult cal = reference::calibrate(trackers_of(*data, offsets, worn));
    if (!cal.ok()) {
      r.error = cal.error;
      return truth;
    }
    r.calibrated_height_m = cal.body.height_m;
    r.arm_scale = cal.body.arm_scale;
    sim::BuildResult solved_model = sim::build_humanoid(reference::calibrated_spec(cal.body, kMassKg));
    if (!solved_model) {
      r.error = solved_model.error;
      return truth;
    }
    reference::IkCreated ik = reference::make_ik_model(*solved_model.model, cal.body);
    if (!ik.model) {
      r.error = ik.error;
      return truth;
    }
    truth.solved = std::move(solved_model.model);
    truth.ik = std::move(ik.model);
    truth.jerk = jerk_sums(truth.joints);
    r.source_jitter_mps3 = jitter(truth.jerk, truth.joints.size(), truth.dt_s);
  } catch (const std::exception& e) {
    r.error = opt.clip + ": " + e.what();
  }
  return truth;
}

IkEvalResult run_ik_eval(const IkEvalOptions& opt) {
  IkEvalResult r;
  const IkSetup setup = prepare_ik_eval(opt, r);
  if (!r.error.empty()) return r;
  for (const char* c : {"clean", "noise", "dropouts"}) {
    r.runs.push_back(run_condition(c, setup, *setup.ik, *setup.solved, opt));
  }
  // The same noise through the solver's input filter (1-euro, default settings).
  reference::IkModel filtered = *setup.ik;
  filtered.options.input_filter = true;
  IkRun run = run_condition("noise", setup, filtered, *setup.solved, opt);
  run.condition = "noise_filtered";
  r.runs.push_back(std::move(run));
  return r;
}

}  // namespace tonus::experiments
