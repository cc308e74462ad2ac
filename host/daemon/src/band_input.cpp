#include "tonus/host/daemon/band_input.hpp"

#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "tonus/host/daemon/candump_replay.hpp"
#include "tonus/host/transport/host_clock.hpp"
#include "tonus/protocol/payloads.hpp"

extern char** environ;

namespace tonus::daemon {

// The spawned simulator: one child at a time, its link on a socketpair (the
// child's fd 3). Replaced when the link has to be reopened.
struct BandInput::SimChild {
  pid_t pid = 0;

  void reap() {
    if (pid <= 0) return;
    ::kill(pid, SIGTERM);
    for (int i = 0; i < 50; ++i) {
      if (::waitpid(pid, nullptr, WNOHANG) == pid) {
        pid = 0;
        return;
      }
      ::usleep(2000);
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    pid = 0;
  }

  // The host's end of the link, or -1 with `error`.
  int spawn(const std::string& path, std::vector<std::string> args, std::string& error) {
    reap();
    int sv[2] = {-1, -1};
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) {
      error = "socketpair failed";
      return -1;
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, sv[1], 3);  // dup2 clears close-on-exec
    std::vector<std::string> argv_s{path};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    argv.reserve(argv_s.size() + 1);
    for (std::string& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid, path.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    ::close(sv[1]);
    if (rc != 0) {
      ::close(sv[0]);
      pid = 0;
      error = fmt::format("cannot start the band simulator {}: {}", path, std::strerror(rc));
      return -1;
    }
    return sv[0];
  }
};

BandInput::BandInput(const BandConfig& config, PhysicsCore& core, std::string tools_dir)
    : config_(config), core_(core), tools_dir_(std::move(tools_dir)), child_(std::make_unique<SimChild>()) {}

BandInput::~BandInput() { stop(); }

void BandInput::start() {
  if (thread_.joinable() || config_.source == BandSource::none) return;
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void BandInput::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  child_->reap();
  const std::lock_guard<std::mutex> lock(mutex_);
  for (auto& p : pending_) p->done.set_value("the band thread stopped");
  pending_.clear();
}

std::future<std::string> BandInput::calibrate(const std::string& command, double duration_s) {
  auto p = std::make_unique<Pending>();
  p->command = command;
  p->duration_s = duration_s;
  std::future<std::string> f = p->done.get_future();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!thread_.joinable()) {
    p->done.set_value("no band is configured");
  } else {
    pending_.push_back(std::move(p));
  }
  return f;
}

BandStatus BandInput::status() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  BandStatus s = status_;
  s.calibrated = calibrated_.load(std::memory_order_relaxed);
  return s;
}

host::ReconnectingBandLink::Opener BandInput::make_opener() {
  const BandConfig& c = config_;
  const auto node = static_cast<std::uint8_t>(c.can_node);
  switch (c.source) {
    case BandSource::hid: {
      const std::wstring serial(c.serial.begin(), c.serial.end());
      return host::hidapi_opener(c.vid, c.pid, serial);
    }
    case BandSource::can: return host::socketcan_opener(c.can_interface, node, c.can_id_base);
    case BandSource::socket:
      return c.sim_link == SimLink::hid ? host::seqpacket_hid_opener(c.sim_socket)
                                        : host::seqpacket_can_opener(c.sim_socket, node, c.can_id_base);
    case BandSource::candump:
      return [path = c.candump_path, loop = c.candump_loop, node,
              base = c.can_id_base](std::string& error) -> std::unique_ptr<host::BandLink> {
        auto t = CandumpReplay::open(path, loop, error);
        if (t == nullptr) return nullptr;
        return std::make_unique<host::CanBandLink>(std::move(t), node, base);
      };
    case BandSource::sim:
    case BandSource::none: break;
  }
  // The simulator, spawned afresh at every (re)open.
  return [this](std::string& error) -> std::unique_ptr<host::BandLink> {
    const BandConfig& b = config_;
    const std::string path = b.sim_path.empty() ? tools_dir_ + "/tonus-band-sim" : b.sim_path;
    std::vector<std::string> args;
    if (!b.sim_recording.empty()) {
      args = {"--recording", b.sim_recording};
    } else {
      args = {"--synthetic", b.sim_synthetic, "--seed", std::to_string(b.sim_seed)};
    }
    // 0: as long as tonusd runs (a day: the simulator's longest run; the link reopens a new one after).
    args.insert(args.end(), {"--seconds", fmt::format("{}", b.sim_seconds > 0.0 ? b.sim_seconds : 86400.0)});
    args.insert(args.end(), {b.sim_link == SimLink::hid ? "--hid-fd" : "--can-fd", "3", "--quiet"});
    args.insert(args.end(), b.sim_args.begin(), b.sim_args.end());
    const int fd = child_->spawn(path, args, error);
    if (fd < 0) return nullptr;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.sim_pid = child_->pid;
    }
    if (b.sim_link == SimLink::hid) {
      return std::make_unique<host::HidBandLink>(std::make_unique<host::SeqpacketHidTransport>(fd));
    }
    return std::make_unique<host::CanBandLink>(std::make_unique<host::SeqpacketCanTransport>(fd),
                                               static_cast<std::uint8_t>(b.can_node), b.can_id_base);
  };
}

void BandInput::on_connected(host::BandLink& link) {
  sync_ = std::make_unique<host::ClockSync>();  // a new link may be a new device, or a rebooted one
  proto::Request req = proto::make_request(proto::Opcode::get_device_info, token_++);
  const std::optional<proto::Response> rsp = link.transact(req, 500, stream_sink());
  proto::DeviceInfo info{};
  std::string line;
  if (!rsp || rsp->status != proto::Status::ok || proto::read_payload(*rsp, info) != proto::Error::ok) {
    line = "a band that did not say who it is (get_device_info failed)";
    spdlog::warn("band: connected, but get_device_info failed; streaming anyway");
  } else {
    line = fmt::format(
        "firmware {}.{}.{} (build {:08x}), protocol {}.{}, serial {:016x}, hardware rev {}, {} channels, {} groups, "
        "{} Hz sampling, {} Hz reports, transports 0x{:02x}, features 0x{:x}, boot {}",
        info.firmware_major, info.firmware_minor, info.firmware_patch, info.build_id, info.protocol_version,
        info.protocol_minor, info.serial, info.hardware_revision, info.channel_count, info.group_count,
        info.sample_rate_hz, info.report_rate_hz, info.transports, info.features, info.boot_count);
    spdlog::info("band: connected: {}", line);
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  status_.connected = true;
  status_.device = line;
}

void BandInput::on_stream(const host::LinkEvent& ev) {
  BandSample s;
  s.arrival_us = ev.rx_host_us;
  s.sequence = ev.stream.sequence;
  calibrated_.store((ev.stream.status & proto::status_bit::calibrated) != 0, std::memory_order_relaxed);
  s.levels.fill(std::nan(""));  // groups the band does not have keep their last (or the safe default)
  const std::size_t n = std::min<std::size_t>(ev.stream.group_count, s.levels.size());
  for (std::size_t g = 0; g < n; ++g) s.levels[g] = static_cast<double>(ev.stream.levels[g]) / proto::kLevelMax;
  if (sync_ && sync_->ready()) {
    const double device_us = static_cast<double>(sync_->extend(ev.stream.device_time_us));
    s.sampled_host_us = static_cast<std::int64_t>(std::llround(sync_->host_from_device_us(device_us)));
  }
  core_.push_band(s);
}

host::BandLink::StreamSink BandInput::stream_sink() {
  // Reports that arrive while a command waits for its answer (arrival: when the wait saw them).
  return [this](const proto::StreamMessage& m) {
    host::LinkEvent ev;
    ev.kind = host::LinkEvent::Kind::stream;
    ev.stream = m;
    ev.rx_host_us = host::steady_now_us();
    on_stream(ev);
  };
}

void BandInput::serve_pending(host::BandLink& link) {
  std::vector<std::unique_ptr<Pending>> work;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    work.swap(pending_);
  }
  for (auto& p : work) {
    proto::Request req;
    if (p->command == "abort") {
      req = proto::make_request(proto::Opcode::calibration_abort, token_++);
    } else {
      proto::CalibrationStart cs;
      cs.phase = p->command == "rest" ? proto::CalibrationPhase::rest : proto::CalibrationPhase::max_contraction;
      cs.duration_ms = static_cast<std::uint16_t>(std::clamp(p->duration_s * 1e3, 100.0, 60000.0));
      proto::make_request(proto::Opcode::calibration_start, token_++, cs, req);
    }
    const std::optional<proto::Response> rsp = link.transact(req, 500, stream_sink());
    if (!rsp) {
      p->done.set_value("the band did not answer within 500 ms");
    } else if (rsp->status != proto::Status::ok) {
      p->done.set_value(fmt::format("the band refused: status {}", static_cast<int>(rsp->status)));
    } else {
      spdlog::info("band: calibration {} started", p->command);
      p->done.set_value("");
    }
  }
}

void BandInput::run() {
  // A lost band is looked for again at least every second (a replugged USB
  // band re-enumerated, a restarted simulator reconnected).
  host::ReconnectPolicy policy;
  policy.max_retry = std::chrono::milliseconds(1000);
  host::ReconnectingBandLink link(make_opener(), policy);
  auto next_sync = std::chrono::steady_clock::now();
  const auto sync_every = std::chrono::microseconds(static_cast<std::int64_t>(config_.time_sync_interval_s * 1e6));
  std::string last_error;
  while (!stop_.load()) {
    const host::LinkEvent ev = link.poll(10);
    switch (ev.kind) {
      case host::LinkEvent::Kind::stream: on_stream(ev); break;
      case host::LinkEvent::Kind::reconnected: on_connected(link); break;
      case host::LinkEvent::Kind::disconnected: {
        spdlog::warn("band: link lost ({}); reopening", link.last_error());
        const std::lock_guard<std::mutex> lock(mutex_);
        status_.connected = false;
        break;
      }
      default: break;
    }
    if (!link.connected()) {
      if (link.last_error() != last_error) {
        last_error = link.last_error();
        if (!last_error.empty()) spdlog::warn("band: cannot open the link: {}", last_error);
      }
      // Nothing to do without a link but to answer the waiting commands.
      const std::lock_guard<std::mutex> lock(mutex_);
      for (auto& p : pending_) p->done.set_value("no band connected");
      pending_.clear();
      continue;
    }
    serve_pending(link);
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_sync && config_.source != BandSource::candump) {  // a recording cannot answer
      next_sync = now + sync_every;
      if (const auto sample = host::exchange_time_sync(link, token_++, 100, stream_sink())) sync_->add(*sample);
    }
    const host::LinkStats st = link.stats();
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.link = st;
    if (sync_) {
      status_.clock_synced = sync_->ready();
      status_.clock_offset_us = sync_->ready() ? sync_->offset_us_at(static_cast<double>(host::steady_now_us())) : 0.0;
      status_.clock_drift_ppm = sync_->drift_ppm();
      status_.min_round_trip_us = sync_->min_round_trip_us();
    }
  }
}

}  // namespace tonus::daemon
