#include "tonus/host/daemon/tracker_input.hpp"

#include <algorithm>
#include <filesystem>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "tonus/host/daemon/sender_frames.hpp"
#include "tonus/host/reference/body_balance.hpp"
#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/host/reference/calibration.hpp"
#include "tonus/host/reference/tracker_ik.hpp"
#include "tonus/host/transport/host_clock.hpp"
#include "tonus/host/vmc/receiver.hpp"
#include "tonus/sim/humanoid.hpp"

namespace tonus::daemon {

std::string default_bvh_path() { return std::string(TONUS_DATA_DIR) + "/cmu_02_walk.bvh"; }

// The VMC source: the receiver, and what turns its frames into poses.
struct TrackerInput::Vmc {
  std::unique_ptr<vmc::VmcReceiver> receiver;
  // performer mode
  std::optional<reference::BodyRetarget> retarget;
  reference::BodyRetargetState retarget_state;
  // tracker mode: calibrated from the first frame with the head and both
  // hands (the performer stands in a T-pose when tracking starts), positions
  // scaled so the performer's height is the humanoid's.
  std::optional<reference::IkModel> ik;
  reference::IkState ik_state;
  reference::IkOutput ik_out;
  double scale = 1.0;
  std::string note;  // what happened, for the log (set on the tracker thread, logged there)
  // performer mode with tracker.balance = "online": the sender's frame time
  // measured over its first frames, then every sample through the online
  // balance filter (its output comes the look-ahead later).
  std::optional<reference::BodyBalance> balance;
  bool balance_refused = false;                // the filter could not be set up: the stream plays uncorrected (logged)
  std::vector<std::int64_t> arrivals;          // until the frame time is known
  std::vector<reference::BodySample> waiting;  // the samples that came meanwhile
  reference::BodySample balanced;
};

namespace {

// Frames over which the sender's frame time is measured (the median interval).
constexpr std::size_t kRateFrames = 30;

}  // namespace

TrackerInput::TrackerInput(const TrackerConfig& config, const sim::Model& model, PhysicsCore& core)
    : config_(config), model_(model), core_(core) {}

TrackerInput::~TrackerInput() { stop(); }

bool TrackerInput::start(std::string& error) {
  if (thread_.joinable() || config_.source == TrackerSource::none) return true;
  stop_.store(false);
  if (config_.source == TrackerSource::bvh) {
    const std::string path = config_.bvh_path.empty() ? default_bvh_path() : config_.bvh_path;
    balance::BalanceStageOptions balance;
    balance.mode = config_.balance;
    balance.lookahead_s = config_.balance_lookahead_s;
    clip_ = reference::clip_to_reference(model_, path, balance);
    if (!clip_.ok()) {
      error = fmt::format("tracker.bvh_path = \"{}\": {}", path, clip_.error);
      return false;
    }
    if (clip_.qpos.size() <= clip_.first_frame || !(clip_.dt_s > 0.0)) {
      error = fmt::format("tracker.bvh_path = \"{}\": no frames to play", path);
      return false;
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.source = fmt::format("bvh {} ({} frames at {:.0f} Hz{})", path, clip_.qpos.size() - clip_.first_frame,
                                   1.0 / clip_.dt_s, config_.bvh_loop ? ", looping" : "");
      status_.balance = clip_.balance;
    }
    spdlog::info("tracker: {}", status_.source);
    if (!clip_.balance.empty()) spdlog::info("tracker: {}", clip_.balance);
    thread_ = std::thread([this] { run_bvh(); });
    return true;
  }
  vmc::ReceiverOptions o;
  o.address = config_.listen_address;
  o.port = config_.listen_port;
  o.mode = config_.vmc_mode == VmcMode::performer ? vmc::ReceiverMode::performer : vmc::ReceiverMode::tracker;
  vmc_ = std::make_unique<Vmc>();
  vmc_->receiver = std::make_unique<vmc::VmcReceiver>(o);
  if (!vmc_->receiver->ok()) {
    error = fmt::format("tracker.listen_address = \"{}\", tracker.listen_port = {}: {}", config_.listen_address,
                        config_.listen_port, vmc_->receiver->error());
    vmc_.reset();
    return false;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.source = fmt::format("vmc {} mode on {}:{}", to_string(config_.vmc_mode), config_.listen_address,
                                 vmc_->receiver->port());
  }
  spdlog::info("tracker: {}", status_.source);
  thread_ = std::thread([this] { run_vmc(); });
  return true;
}

int TrackerInput::vmc_port() const { return vmc_ && vmc_->receiver ? vmc_->receiver->port() : 0; }

void TrackerInput::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

TrackerStatus TrackerInput::status() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void TrackerInput::count_frame(bool pushed) {
  const std::int64_t now = host::steady_now_us();
  const std::lock_guard<std::mutex> lock(mutex_);
  ++(pushed ? status_.frames : status_.dropped);
  ++rate_window_frames_;
  if (rate_window_start_us_ == 0) rate_window_start_us_ = now;
  if (now - rate_window_start_us_ >= 1'000'000) {
    status_.rate_hz = static_cast<double>(rate_window_frames_) * 1e6 / static_cast<double>(now - rate_window_start_us_);
    rate_window_start_us_ = now;
    rate_window_frames_ = 0;
  }
}

void TrackerInput::run_bvh() {
  const auto dt_us = static_cast<std::int64_t>(std::llround(clip_.dt_s * 1e6));
  std::int64_t t_us = host::steady_now_us();
  std::size_t k = clip_.first_frame;
  PoseSample s;
  bool cut = false;
  while (!stop_.load()) {
    if (k >= clip_.qpos.size()) {
      if (!config_.bvh_loop) return;  // the stream ends: the physics core holds, then eases to neutral
      k = clip_.first_frame;
      cut = true;
      const std::lock_guard<std::mutex> lock(mutex_);
      ++status_.loops;
    }
    // Sleep in short steps so stop() is prompt even for a slow clip.
    while (!stop_.load() && host::steady_now_us() < t_us) {
      std::this_thread::sleep_for(
          std::chrono::microseconds(std::min<std::int64_t>(t_us - host::steady_now_us(), 5000)));
    }
    s.t_us = t_us;
    s.qpos = clip_.qpos[k];
    s.cut = std::exchange(cut, false);
    count_frame(core_.push_pose(s));
    ++k;
    t_us += dt_us;
  }
}

void TrackerInput::run_vmc() {
  Vmc& v = *vmc_;
  // A sender's frame comes in several bundles (the receiver reports each), so
  // everything one receive() call decoded is merged and solved once.
  reference::BodySample body;
  reference::TrackerFrame trackers;
  bool pending = false;
  std::int64_t arrival_us = 0;
  // With the online balance filter, the sender's own frames (sender_frames.hpp).
  const bool balancing = config_.vmc_mode == VmcMode::performer && config_.balance == balance::BalanceMode::online;
  SenderFrames framer;
  std::vector<SenderFrame> finished;
  v.receiver->set_handler([&](const vmc::ReceivedFrame& f) {
    if (balancing && f.mode == vmc::ReceiverMode::performer) {
      const auto& skeleton = v.receiver->skeleton();
      framer.add(f.body, f.arrival_us, skeleton ? &skeleton->present : nullptr, finished);
      return;
    }
    if (f.mode == vmc::ReceiverMode::performer) {
      for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
        if (!f.body.present[b]) continue;
        body.present[b] = true;
        body.local[b] = f.body.local[b];
      }
      if (f.body.root_present) {
        body.root_present = true;
        body.root_position = f.body.root_position;
        body.root_rotation = f.body.root_rotation;
      }
    } else {
      for (std::size_t t = 0; t < reference::kTrackerCount; ++t) {
        if (f.trackers.pose[t].valid) trackers.pose[t] = f.trackers.pose[t];
      }
    }
    arrival_us = f.arrival_us;
    pending = true;
  });
  PoseSample s;
  while (!stop_.load()) {
    v.receiver->receive(20);
    {
      const vmc::ReceiverCounters& c = v.receiver->counters();
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.vmc_messages = c.messages;
      status_.vmc_ignored = c.ignored;
      status_.vmc_malformed = c.malformed;
    }
    if (balancing) {
      for (const SenderFrame& frame : finished) {
        s.t_us = frame.arrival_us;
        const bool solved =
            v.balance_refused ? solve_body(frame.body, s.qpos) : balance_body(frame.body, frame.arrival_us, s.qpos);
        if (solved) count_frame(core_.push_pose(s));
      }
      finished.clear();
      continue;
    }
    if (!pending) continue;
    pending = false;
    s.t_us = arrival_us;
    const bool solved = config_.vmc_mode == VmcMode::performer ? solve_body(body, s.qpos)
                                                               : solve_trackers(trackers, arrival_us, s.qpos);
    body = reference::BodySample{};
    trackers = reference::TrackerFrame{};
    if (solved) count_frame(core_.push_pose(s));
  }
}

bool TrackerInput::solve_body(const reference::BodySample& body, Qpos& qpos) {
  Vmc& v = *vmc_;
  if (!v.retarget && v.receiver->skeleton()) {
    reference::BodyRetargetBuild b = reference::BodyRetarget::create(model_, *v.receiver->skeleton());
    if (!b.ok()) {
      spdlog::warn("tracker: the VMC sender's skeleton cannot be retargeted: {}", b.error);
      v.receiver->reset_skeleton();
      return false;
    }
    v.retarget = std::move(*b.retarget);
    spdlog::info("tracker: VMC performer skeleton learnt (scale {:.3f})", v.retarget->scale());
  }
  if (!v.retarget) return false;
  qpos = model_.qpos0;
  v.retarget->solve(body, v.retarget_state, qpos);
  return true;
}

bool TrackerInput::balance_body(const reference::BodySample& body, std::int64_t arrival_us, Qpos& qpos) {
  Vmc& v = *vmc_;
  if (!v.receiver->skeleton()) return false;  // the sender's skeleton is not known yet
  if (!v.balance) {
    v.arrivals.push_back(arrival_us);
    v.waiting.push_back(body);
    if (v.arrivals.size() < kRateFrames) return false;
    std::vector<double> gaps;
    for (std::size_t k = 1; k < v.arrivals.size(); ++k) {
      gaps.push_back(static_cast<double>(v.arrivals[k] - v.arrivals[k - 1]) * 1e-6);
    }
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
    const double dt = gaps[gaps.size() / 2];
    balance::OnlineOptions o;
    o.dt_s = dt;
    o.lookahead_s = config_.balance_lookahead_s;
    reference::BodyBalance::Created made =
        dt >= 1e-3 && dt <= 0.1 ? reference::BodyBalance::create(*v.receiver->skeleton(), o)
                                : reference::BodyBalance::Created{"the sender's frame rate is not 10..1000 Hz", {}};
    if (!made) {
      spdlog::warn(
          "tracker: balance (online) cannot run on this VMC performer ({:.1f} Hz measured): {}; the stream "
          "plays uncorrected",
          1.0 / dt, made.error);
      v.balance_refused = true;
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.balance = "off (refused: " + made.error + ")";
      return solve_body(body, qpos);
    }
    v.balance = std::move(*made.balance);
    const std::string note = fmt::format(
        "online on the VMC performer stream: the sender at {:.1f} Hz (median of {} "
        "frames), look-ahead {} frames ({:.0f} ms)",
        1.0 / dt, gaps.size(), v.balance->lookahead_frames(),
        static_cast<double>(v.balance->lookahead_frames()) * dt * 1e3);
    spdlog::info("tracker: balance {}", note);
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.balance = note;
    }
    // The samples that came while the rate was measured fill the window (their
    // own outputs are past); the newest goes on below.
    v.waiting.pop_back();
    for (const reference::BodySample& w : v.waiting) (void)v.balance->push(w, v.balanced);
    v.waiting = {};
    v.arrivals = {};
  }
  if (!v.balance->push(body, v.balanced)) return false;
  return solve_body(v.balanced, qpos);
}

bool TrackerInput::solve_trackers(reference::TrackerFrame frame, std::int64_t arrival_us, Qpos& qpos) {
  Vmc& v = *vmc_;
  frame.time_s = static_cast<double>(arrival_us) * 1e-6;
  if (!v.ik) {
    const reference::CalibrationResult raw = reference::calibrate(frame);
    if (!raw.ok()) return false;                                 // waiting for the head and both hands
    v.scale = sim::HumanoidSpec{}.height_m / raw.body.height_m;  // tonusd drives the default humanoid
    for (auto& p : frame.pose) p.pos_m *= v.scale;
    const reference::CalibrationResult cal = reference::calibrate(frame);
    if (!cal.ok()) return false;
    reference::IkCreated ik = reference::make_ik_model(model_, cal.body);
    if (!ik.model) {
      spdlog::warn("tracker: IK cannot be set up: {}", ik.error);
      return false;
    }
    v.ik = std::move(*ik.model);
    spdlog::info("tracker: calibrated from the first full frame: performer {:.2f} m, scaled by {:.3f}",
                 raw.body.height_m, v.scale);
  } else {
    for (auto& p : frame.pose) p.pos_m *= v.scale;
  }
  reference::solve_ik(*v.ik, v.ik_state, frame, v.ik_out);
  qpos = v.ik_out.qpos;
  return true;
}

}  // namespace tonus::daemon
