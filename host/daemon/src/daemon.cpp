#include "tonus/host/daemon/daemon.hpp"

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "tonus/host/daemon/config_file.hpp"
#include "tonus/host/transport/host_clock.hpp"
#include "tonus/host/viewer/server.hpp"
#include "tonus/sim/humanoid.hpp"

namespace tonus::daemon {
namespace {

constexpr std::array<std::string_view, 4> kGroupNames{"right_arm", "left_arm", "trunk", "legs"};

double wall_s() { return static_cast<double>(host::steady_now_us()) * 1e-6; }

double cpu_s() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const auto sec = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return sec(ru.ru_utime) + sec(ru.ru_stime);
}

avatar::Feedforward feedforward_of(FeedforwardChoice f) {
  switch (f) {
    case FeedforwardChoice::simulation: return avatar::Feedforward::simulation;
    case FeedforwardChoice::inverse_dynamics: return avatar::Feedforward::inverse_dynamics;
    case FeedforwardChoice::none: return avatar::Feedforward::none;
  }
  return avatar::Feedforward::simulation;
}

nlohmann::json levels_json(const Levels& l) {
  nlohmann::json j;
  for (std::size_t g = 0; g < l.size(); ++g) j[std::string(kGroupNames[g])] = l[g];
  return j;
}

}  // namespace

std::unique_ptr<Daemon> Daemon::create(const DaemonConfig& config, std::string tools_dir, std::string& error) {
  if (error = validate(config); !error.empty()) return nullptr;
  if (error = check_files(config); !error.empty()) return nullptr;
  auto d = std::unique_ptr<Daemon>(new Daemon());
  d->config_ = config;
  sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  if (!built) {
    error = "the humanoid: " + built.error;
    return nullptr;
  }
  d->model_ = std::move(built.model);
  d->model_->timestep_s = 1.0 / config.physics.rate_hz;  // the step is the physics thread's period
  PhysicsCoreConfig pc;
  pc.avatar.feedforward = feedforward_of(config.physics.feedforward);
  pc.avatar.stiffness.max_rate_per_s = config.physics.stiffness_rate_per_s;
  pc.stiffness = config.band.stiffness;
  pc.avatar.stiffness.initial = config.band.stiffness.safe_default[0];
  pc.pose = config.tracker.buffer;
  if (config.viewer.enabled) {  // snapshots for the viewer at twice its frame rate
    pc.viewer_every_ticks =
        std::max(1, static_cast<int>(std::lround(config.physics.rate_hz / (2.0 * config.viewer.rate_hz))));
  }
  d->core_ = PhysicsCore::create(*d->model_, pc, error);
  if (!d->core_) return nullptr;
  PacingConfig pace;
  pace.rate_hz = config.physics.rate_hz;
  pace.max_catch_up_ticks = config.physics.max_catch_up_ticks;
  pace.realtime_priority = config.physics.realtime_priority;
  pace.lock_memory = config.physics.lock_memory;
  d->physics_ = std::make_unique<PhysicsThread>(*d->core_, pace);
  d->band_ = std::make_unique<BandInput>(config.band, *d->core_, std::move(tools_dir));
  d->tracker_ = std::make_unique<TrackerInput>(config.tracker, *d->model_, *d->core_);
  d->output_ = std::make_unique<VmcOutput>(config.output, *d->model_, *d->core_);
  return d;
}

Daemon::~Daemon() { stop(); }

bool Daemon::record_to(const std::string& path, std::string& error) {
  recording::Header h;
  h.config_toml = to_toml(config_);
  h.rate_hz = config_.physics.rate_hz;
  h.nq = model_->nq;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  h.created_utc = fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                              utc.tm_hour, utc.tm_min, utc.tm_sec);
  h.tonus_version = TONUS_VERSION;
  recorder_ = Recorder::create(path, h, error);
  if (!recorder_) return false;
  record_path_ = path;
  core_->set_recorder(recorder_.get());
  output_->set_recorder(recorder_.get());
  return true;
}

std::optional<recording::Reader> Daemon::open_recording(const std::string& path, DaemonConfig& config,
                                                        std::string& error) {
  std::optional<recording::Reader> r = recording::Reader::open(path, error);
  if (!r) return std::nullopt;
  DaemonConfig c;
  if (const std::string e = parse_config(r->header().config_toml, path + " (its configuration)", c); !e.empty()) {
    error = e;
    return std::nullopt;
  }
  config = c;
  return r;
}

void Daemon::replay_from(recording::Reader reader, double speed) {
  if (reader.header().nq != model_->nq) {
    spdlog::warn("replay: the recording's model has {} coordinates, this one {}: it will diverge", reader.header().nq,
                 model_->nq);
  }
  replay_ = std::make_unique<ReplayDriver>(*core_, output_.get(), std::move(reader), speed);
}

bool Daemon::start_viewer(std::string& error) {
  if (!config_.viewer.enabled) return true;
  viewer_ = std::make_unique<ViewerFeed>(config_.viewer, *model_, *core_, replay_ ? "replay" : "live");
  ViewerFeed::Playback playback = [this](const viewer::PlaybackMessage& m) -> std::string {
    if (!replay_) return "not playing a recording (tonusd --replay FILE)";
    switch (m.action) {
      case viewer::PlaybackAction::play: replay_->resume(); break;
      case viewer::PlaybackAction::pause: replay_->pause(); break;
      case viewer::PlaybackAction::seek: replay_->seek(m.position_s); break;
    }
    return {};
  };
  if (!viewer_->start(
          error, control_.get(), replay_ != nullptr, [this](viewer::Frame& f) { viewer_extras(f); }, playback)) {
    viewer_.reset();
    return false;
  }
  // An interface: scripts and tests read this line.
  std::fputs(fmt::format("viewer: {}\n", viewer_->url()).c_str(), stdout);
  std::fflush(stdout);
  return true;
}

void Daemon::viewer_extras(viewer::Frame& f) {
  const BandStatus b = band_->status();
  IntervalFigures interval;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    interval = last_interval_;
  }
  f.band.source = replay_ ? "replay" : std::string(to_string(config_.band.source));
  f.band.connected = b.connected;
  f.band.calibrated = b.calibrated;
  f.band.latency_p50_ms = interval.band_latency_p50_us * 1e-3;
  f.band.latency_p99_ms = interval.band_latency_p99_us * 1e-3;
  f.band.reports = b.link.delivered;
  f.band.lost = b.link.lost;
  f.metrics.ticks = replay_ ? f.tick : physics_->ticks();
  f.metrics.overruns = physics_->overruns();
  f.metrics.tick_p50_us = interval.p50_us;
  f.metrics.tick_p99_us = interval.p99_us;
  f.metrics.tick_max_us = interval.max_us;
  f.metrics.tracker_rate_hz = replay_ ? 0.0 : tracker_->status().rate_hz;
  if (replay_) {
    const ReplayStatus r = replay_->status();
    f.playback = viewer::PlaybackFrame{replay_->duration_s(), r.position_s, !replay_->paused()};
  }
}

bool Daemon::start(std::string& error) {
  // The control API's handler serves the HTTP server and the viewer's page alike.
  control_ = std::make_unique<DaemonControl>(*this);
  if (replay_) {
    if (!output_->open_driven(error)) return false;
    spdlog::info("replay: {:.0f} Hz, VMC to {}:{}", config_.physics.rate_hz, config_.output.host, config_.output.port);
    if (!start_viewer(error)) return false;
    replay_->start();
    started_wall_s_ = wall_s();
    cpu_seconds_ = cpu_s();
    return true;
  }
  if (recorder_) {
    recorder_->start();
    spdlog::info("recording to {}", record_path_);
  }
  // The tracker first: a bad clip or a port in use stops everything before any thread runs.
  if (!tracker_->start(error)) return false;
  // The output thread just below the physics thread (when real time is asked for at all).
  if (!output_->start(error, config_.physics.realtime_priority > 1 ? config_.physics.realtime_priority - 1 : 0)) {
    tracker_->stop();
    return false;
  }
  physics_->start();
  const RealtimeSetup& rt = physics_->realtime();
  if (config_.physics.realtime_priority > 0) {
    if (rt.priority_set) {
      spdlog::info("physics: SCHED_FIFO priority {}", config_.physics.realtime_priority);
    } else {
      spdlog::warn("physics: running without real-time priority ({})", rt.priority_error);
    }
  }
  if (config_.physics.lock_memory) {
    if (rt.memory_locked) {
      spdlog::info("physics: memory locked");
    } else {
      spdlog::warn("physics: memory not locked ({})", rt.lock_error);
    }
  }
  spdlog::info("physics: {:.0f} Hz, feedforward {}, VMC to {}:{} at {:.0f} Hz", config_.physics.rate_hz,
               to_string(config_.physics.feedforward), config_.output.host, config_.output.port,
               config_.output.rate_hz);
  if (config_.control.enabled) {
    control_server_ = std::make_unique<control::ControlServer>(*control_);
    const std::string e =
        control_server_->start(config_.control.address, config_.control.port, config_.control.allow_remote);
    if (!e.empty()) {
      error = fmt::format("control.address = \"{}\", control.port = {}: {}", config_.control.address,
                          config_.control.port, e);
      control_server_.reset();
      physics_->stop();
      output_->stop();
      tracker_->stop();
      return false;
    }
    spdlog::info("control: http://{}:{}/status (tonus ctl)", config_.control.address, control_server_->port());
  }
  if (!start_viewer(error)) {
    if (control_server_) control_server_->stop();
    physics_->stop();
    output_->stop();
    tracker_->stop();
    return false;
  }
  band_->start();
  started_wall_s_ = wall_s();
  cpu_seconds_ = cpu_s();
  return true;
}

void Daemon::stop() {
  if (!physics_) return;
  const bool was_running = started_wall_s_ > 0.0;
  if (viewer_) viewer_->stop();
  if (control_server_) control_server_->stop();
  if (replay_) replay_->stop();
  band_->stop();
  tracker_->stop();
  output_->stop();
  physics_->stop();
  if (recorder_) recorder_->stop();  // after the physics: the last ticks go into the last chunk
  if (was_running) {
    run_seconds_ = wall_s() - started_wall_s_;
    cpu_seconds_ = cpu_s() - cpu_seconds_;
    started_wall_s_ = 0.0;
    drain_events();
  }
}

std::uint32_t Daemon::spawn_gift(GiftKind kind, sim::Bone bone, const avatar::ThrowBall* ball,
                                 const avatar::DropCube* cube, std::string& error) {
  Command c;
  c.kind = Command::Kind::gift;
  c.id = next_id_.fetch_add(1);
  c.gift = kind;
  if (ball != nullptr) c.ball = *ball;
  if (cube != nullptr) c.cube = *cube;
  c.ball.target = bone;
  c.cube.target = bone;
  if (!core_->push_command(c)) {
    error = "the command queue is full";
    return 0;
  }
  return c.id;
}

bool Daemon::clear_gifts() {
  Command c;
  c.kind = Command::Kind::clear_gifts;
  c.id = next_id_.fetch_add(1);
  return core_->push_command(c);
}

bool Daemon::set_stiffness_override(const std::optional<Levels>& levels) {
  Command c;
  c.kind = levels ? Command::Kind::stiffness_override : Command::Kind::stiffness_release;
  c.id = next_id_.fetch_add(1);
  if (levels) c.levels = *levels;
  return core_->push_command(c);
}

std::future<std::string> Daemon::calibrate(const std::string& command) { return band_->calibrate(command); }

void Daemon::drain_events() {
  Event e;
  while (core_->events().try_dequeue(e)) {
    ++events_seen_;
    const std::string bone(sim::name(e.bone));
    switch (e.kind) {
      case Event::Kind::gift_spawned: {
        spdlog::info("gift {}: a {} at the {} (stiffness {:.2f})", e.id, to_string(e.gift), bone, e.stiffness);
        const std::lock_guard<std::mutex> lock(mutex_);
        gifts_.push_back(
            {e.id, std::string(to_string(e.gift)), bone, e.time_s, e.stiffness, e.natural_hz, 0.0, false, ""});
        break;
      }
      case Event::Kind::gift_refused: {
        spdlog::warn("gift {}: a {} at the {} refused: {}", e.id, to_string(e.gift), bone, avatar::to_string(e.error));
        const std::lock_guard<std::mutex> lock(mutex_);
        gifts_.push_back({e.id, std::string(to_string(e.gift)), bone, e.time_s, 0.0, 0.0, 0.0, false,
                          std::string(avatar::to_string(e.error))});
        break;
      }
      case Event::Kind::gift_reaction: {
        spdlog::info("gift {}: the {} gave {:.1f} mm under the {} (stiffness {:.2f})", e.id, bone,
                     e.peak_deflection_m * 1e3, to_string(e.gift), e.stiffness);
        const std::lock_guard<std::mutex> lock(mutex_);
        for (GiftRecord& g : gifts_) {
          if (g.id == e.id && g.refused.empty()) {
            g.peak_deflection_m = e.peak_deflection_m;
            g.measured = true;
          }
        }
        break;
      }
      case Event::Kind::gifts_cleared: spdlog::info("gifts cleared"); break;
      case Event::Kind::avatar_reset:
        spdlog::warn("avatar: simulation {} reset (it diverged)", (e.flags & avatar::kResetB) != 0 ? "B" : "A");
        break;
      case Event::Kind::reference_jump: spdlog::info("avatar: the reference jumped; resynced"); break;
      case Event::Kind::band_stale:
        spdlog::warn("band: no report for {:.0f} ms; easing to the safe stiffness",
                     config_.band.stiffness.stale_after_s * 1e3);
        break;
      case Event::Kind::band_live: spdlog::info("band: reports again"); break;
      case Event::Kind::tracker_state: spdlog::info("tracker: {}", to_string(e.pose_state)); break;
      case Event::Kind::stiffness_override:
        spdlog::info("stiffness overridden: {:.2f} {:.2f} {:.2f} {:.2f}", e.levels[0], e.levels[1], e.levels[2],
                     e.levels[3]);
        break;
      case Event::Kind::stiffness_release: spdlog::info("stiffness override released: the band sets it again"); break;
    }
  }
}

void Daemon::log_status() {
  IntervalFigures f;
  if (!physics_->take_interval(f)) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    last_interval_ = f;
  }
  const BandStatus b = band_->status();
  const TrackerStatus t = tracker_->status();
  const OutputStatus o = output_->status();
  Snapshot s;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    s = last_;
  }
  spdlog::info(
      "status: tick p50 {:.0f} us p99 {:.0f} us max {:.0f} us, overruns {} | band {} {} reports, {} lost, latency p50 "
      "{:.1f} ms p99 {:.1f} ms | tracker {:.0f} Hz ({}) | stiffness {:.2f} {:.2f} {:.2f} {:.2f} | objects {} | vmc {} "
      "frames",
      f.p50_us, f.p99_us, f.max_us, f.overruns, b.connected ? "on" : "off", b.link.delivered, b.link.lost,
      f.band_latency_p50_us * 1e-3, f.band_latency_p99_us * 1e-3, t.rate_hz, to_string(s.pose_state), s.stiffness[0],
      s.stiffness[1], s.stiffness[2], s.stiffness[3], s.nobjects, o.frames);
}

void Daemon::run_for(double seconds, const std::atomic<bool>& stop_flag, bool demo_gifts) {
  const double t0 = wall_s();
  std::vector<ScheduledGift> schedule;
  if (demo_gifts) schedule = config_.demo.gifts.empty() ? default_demo_gifts(seconds) : config_.demo.gifts;
  std::size_t next_gift = 0;
  double next_trace = 0.0;
  double next_status = config_.log.status_interval_s;
  bool status_asked = false;
  while (!stop_flag.load() && (seconds <= 0.0 || wall_s() - t0 < seconds) && !(replay_ && replay_->done())) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const double t = wall_s() - t0;
    while (next_gift < schedule.size() && schedule[next_gift].at_s <= t) {
      const ScheduledGift& g = schedule[next_gift++];
      const auto bone = sim::bone_from_name(g.bone);
      avatar::DropCube cube;
      cube.lifetime_s = 3.0;  // the demo's cubes fall off the scene after their reaction is measured
      std::string error;
      if (!bone || spawn_gift(g.kind == "ball" ? GiftKind::ball : GiftKind::cube, *bone, nullptr, &cube, error) == 0) {
        spdlog::warn("demo: gift at {:.1f} s not sent: {}", g.at_s, bone ? error : "unknown bone " + g.bone);
      }
    }
    drain_events();
    if (core_->status_snapshots().update()) {
      const std::lock_guard<std::mutex> lock(mutex_);
      last_ = core_->status_snapshots().read_slot();
      if (t >= next_trace) {
        trace_.push_back({t, last_.stiffness});
        next_trace += 0.5;
      }
    }
    if (config_.log.status_interval_s > 0.0 && t >= next_status) {
      if (!status_asked) {
        physics_->request_interval();
        status_asked = true;
      } else {
        log_status();
        status_asked = false;
        next_status += config_.log.status_interval_s;
      }
    }
  }
}

nlohmann::json Daemon::status_json() const {
  const BandStatus b = band_->status();
  const TrackerStatus t = tracker_->status();
  const OutputStatus o = output_->status();
  nlohmann::json j;
  Snapshot s;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    s = last_;
    j["gifts"] = gifts_.size();
  }
  j["time_s"] = s.time_s;
  j["ticks"] = physics_->ticks();
  j["overruns"] = physics_->overruns();
  j["stiffness"] = levels_json(s.stiffness);
  j["stiffness_override"] = s.override_active;
  j["objects"] = s.nobjects;
  j["band"] = {{"source", to_string(config_.band.source)},
               {"connected", b.connected},
               {"live", s.band_live},
               {"device", b.device},
               {"reports", b.link.delivered},
               {"lost", b.link.lost},
               {"disconnects", b.link.disconnects},
               {"clock_synced", b.clock_synced},
               {"clock_drift_ppm", b.clock_drift_ppm},
               {"sim_pid", b.sim_pid}};
  j["tracker"] = {
      {"source", t.source}, {"state", to_string(s.pose_state)}, {"frames", t.frames},          {"rate_hz", t.rate_hz},
      {"loops", t.loops},   {"vmc_malformed", t.vmc_malformed}, {"vmc_ignored", t.vmc_ignored}};
  j["output"] = {{"frames", o.frames}, {"bundles", o.bundles}, {"send_errors", o.send_errors}};
  return j;
}

nlohmann::json Daemon::summary_json() const {
  const Histogram& cost = physics_->tick_cost();
  const BandStatus b = band_->status();
  const OutputStatus o = output_->status();
  const TrackerStatus t = tracker_->status();
  const CoreStats& cs = core_->stats();
  nlohmann::json j;
  j["seconds"] = run_seconds_;
  j["rate_hz"] = config_.physics.rate_hz;
  j["ticks"] = physics_->ticks();
  j["tick_p50_us"] = cost.quantile_us(0.5);
  j["tick_p99_us"] = cost.quantile_us(0.99);
  j["tick_max_us"] = cost.max_us();
  j["tick_mean_us"] = cost.mean_us();
  j["overruns"] = physics_->overruns();
  j["overruns_from_cost"] = physics_->overruns_from_cost();
  j["skipped_ticks"] = physics_->skipped();
  j["overrun_share"] =
      physics_->ticks() > 0 ? static_cast<double>(physics_->overruns()) / static_cast<double>(physics_->ticks()) : 0.0;
  j["wake_late_p99_us"] = physics_->wake_late().quantile_us(0.99);
  j["wake_late_max_us"] = physics_->wake_late().max_us();
  j["realtime_priority"] = physics_->realtime().priority_set;
  j["memory_locked"] = physics_->realtime().memory_locked;
  j["cpu_share"] = run_seconds_ > 0.0 ? cpu_seconds_ / run_seconds_ : 0.0;
  // Equal hashes, equal outputs (a replay of a recording matches its run).
  j["output_hash"] = fmt::format("{:016x}", cs.output_hash);
  j["vmc_hash"] = fmt::format("{:016x}", o.wire_hash);
  if (recorder_) {
    const RecorderStatus r = recorder_->status();
    j["recording"] = {{"path", record_path_}, {"ticks", r.ticks},           {"chunks", r.chunks},
                      {"bytes", r.bytes},     {"vmc_frames", r.vmc_frames}, {"error", r.error}};
  }
  if (replay_) {
    const ReplayStatus r = replay_->status();
    j["ticks"] = cs.ticks;
    j["replay"] = {{"end", to_string(r.end)},     {"error", r.error},           {"ticks", r.ticks},
                   {"chunks_verified", r.chunks}, {"vmc_frames", r.vmc_frames}, {"position_s", r.position_s}};
  }
  j["vmc_bundles_sent"] = o.bundles;
  j["vmc_frames_sent"] = o.frames;
  j["vmc_send_errors"] = o.send_errors;
  j["band_reports_received"] = b.link.delivered;
  j["band_reports_lost"] = b.link.lost;
  j["band_disconnects"] = b.link.disconnects;
  j["band_device"] = b.device;
  j["band_clock_synced"] = b.clock_synced;
  j["band_clock_drift_ppm"] = b.clock_drift_ppm;
  const Histogram& lat = core_->band_latency();
  j["band_latency_samples"] = lat.count();
  j["band_latency_p50_us"] = lat.quantile_us(0.5);
  j["band_latency_p99_us"] = lat.quantile_us(0.99);
  j["band_latency_max_us"] = lat.max_us();
  const Histogram& wire = output_->report_to_wire();
  j["report_to_vmc_p50_us"] = wire.quantile_us(0.5);
  j["report_to_vmc_p99_us"] = wire.quantile_us(0.99);
  j["report_to_vmc_max_us"] = wire.max_us();
  j["output_period_us"] = 1e6 / config_.output.rate_hz;
  j["tracker_frames"] = t.frames;
  j["tracker_source"] = t.source;
  j["tracker_vmc_messages"] = t.vmc_messages;
  j["tracker_vmc_malformed"] = t.vmc_malformed;
  j["tracker_vmc_ignored"] = t.vmc_ignored;
  j["tracker_balance"] = t.balance;
  j["avatar_resets"] = cs.avatar_resets;
  j["stiffness_min"] = levels_json(cs.stiffness_min);
  j["stiffness_max"] = levels_json(cs.stiffness_max);
  const std::lock_guard<std::mutex> lock(mutex_);
  j["gifts"] = nlohmann::json::array();
  for (const GiftRecord& g : gifts_) {
    nlohmann::json x{{"id", g.id},
                     {"kind", g.kind},
                     {"bone", g.bone},
                     {"at_s", g.at_s},
                     {"stiffness", g.stiffness},
                     {"natural_hz", g.natural_hz},
                     {"peak_deflection_m", g.peak_deflection_m},
                     {"measured", g.measured}};
    if (!g.refused.empty()) x["refused"] = g.refused;
    j["gifts"].push_back(x);
  }
  j["stiffness_trace"] = nlohmann::json::array();
  for (const StiffnessPoint& p : trace_) {
    j["stiffness_trace"].push_back({p.t_s, p.levels[0], p.levels[1], p.levels[2], p.levels[3]});
  }
  return j;
}

std::string Daemon::summary_text() const {
  const nlohmann::json j = summary_json();
  std::string out = fmt::format("tonusd: {:.1f} s at {:.0f} Hz\n", j["seconds"].get<double>(), config_.physics.rate_hz);
  out += "stiffness (applied; right arm, left arm, trunk, legs):\n";
  const auto& trace = j["stiffness_trace"];
  const std::size_t step = std::max<std::size_t>(1, trace.size() / 20);
  for (std::size_t i = 0; i < trace.size(); i += step) {
    const auto& p = trace[i];
    const double v = p[1].get<double>();
    out += fmt::format("  {:6.1f} s  {:.2f} {:.2f} {:.2f} {:.2f}  {}\n", p[0].get<double>(), v, p[2].get<double>(),
                       p[3].get<double>(), p[4].get<double>(),
                       std::string(static_cast<std::size_t>(std::lround(v * 40.0)), '#'));
  }
  out += "gifts:\n";
  for (const auto& g : j["gifts"]) {
    if (g.contains("refused")) {
      out += fmt::format("  {:6.1f} s  {} at the {}: refused ({})\n", g["at_s"].get<double>(),
                         g["kind"].get<std::string>(), g["bone"].get<std::string>(), g["refused"].get<std::string>());
    } else {
      out += fmt::format("  {:6.1f} s  {} at the {}: stiffness {:.2f}, peak deflection {:.1f} mm{}\n",
                         g["at_s"].get<double>(), g["kind"].get<std::string>(), g["bone"].get<std::string>(),
                         g["stiffness"].get<double>(), g["peak_deflection_m"].get<double>() * 1e3,
                         g["measured"].get<bool>() ? "" : " (still measuring at the end)");
    }
  }
  out += fmt::format(
      "ticks: {} (p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us), overruns {} ({:.3f} %; {} from a tick's own cost, the "
      "rest woke late), cpu {:.1f} % of a core\n",
      j["ticks"].get<std::uint64_t>(), j["tick_p50_us"].get<double>(), j["tick_p99_us"].get<double>(),
      j["tick_max_us"].get<double>(), j["overruns"].get<std::uint64_t>(), 100.0 * j["overrun_share"].get<double>(),
      j["overruns_from_cost"].get<std::uint64_t>(), 100.0 * j["cpu_share"].get<double>());
  out += fmt::format(
      "band: {} reports, {} lost; device sample to tick p50 {:.2f} ms, p99 {:.2f} ms; report to VMC p50 {:.2f} ms, "
      "p99 {:.2f} ms (output period {:.1f} ms)\n",
      j["band_reports_received"].get<std::uint64_t>(), j["band_reports_lost"].get<std::uint64_t>(),
      j["band_latency_p50_us"].get<double>() * 1e-3, j["band_latency_p99_us"].get<double>() * 1e-3,
      j["report_to_vmc_p50_us"].get<double>() * 1e-3, j["report_to_vmc_p99_us"].get<double>() * 1e-3,
      j["output_period_us"].get<double>() * 1e-3);
  out += fmt::format("vmc: {} bundles to {}:{}\n", j["vmc_bundles_sent"].get<std::uint64_t>(), config_.output.host,
                     config_.output.port);
  if (j.contains("recording")) {
    const nlohmann::json& r = j["recording"];
    out += fmt::format("recording: {} ({} ticks in {} chunks, {:.1f} MB){}\n", r["path"].get<std::string>(),
                       r["ticks"].get<std::uint64_t>(), r["chunks"].get<std::uint64_t>(),
                       static_cast<double>(r["bytes"].get<std::uint64_t>()) * 1e-6,
                       r["error"].get<std::string>().empty() ? "" : "; " + r["error"].get<std::string>());
  }
  if (j.contains("replay")) {
    const nlohmann::json& r = j["replay"];
    out += fmt::format("replay: {}, {} ticks, {} chunks verified, {} VMC frames{}\n", r["end"].get<std::string>(),
                       r["ticks"].get<std::uint64_t>(), r["chunks_verified"].get<std::uint64_t>(),
                       r["vmc_frames"].get<std::uint64_t>(),
                       r["error"].get<std::string>().empty() ? "" : "; " + r["error"].get<std::string>());
  }
  out += fmt::format("outputs: hash {}, VMC bytes hash {}\n", j["output_hash"].get<std::string>(),
                     j["vmc_hash"].get<std::string>());
  return out;
}

}  // namespace tonus::daemon
