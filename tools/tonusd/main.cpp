// tonusd: the host daemon. Band and trackers in, the avatar at a fixed rate,
// VMC out to the avatar engine. `tonusd --demo` runs with no hardware and no
// config file (docs/daemon.md).
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "tonus/host/daemon/config_file.hpp"
#include "tonus/host/daemon/daemon.hpp"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int /*sig*/) { g_stop.store(true); }

std::string exe_dir() {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

int run(int argc, char** argv) {
  using namespace tonus::daemon;
  CLI::App app{"tonusd: EMG-set stiffness for a physics avatar that follows motion capture, sent out as VMC"};
  std::string config_path, json_path, record_path, replay_path;
  double speed = 1.0;
  bool demo = false, print_config = false, no_realtime = false, no_control = false;
  double seconds = -1.0;
  // Flags that override the file (each names its key in docs/daemon.md).
  std::string band_source, band_socket, sim_synthetic, tracker_source, bvh_path, vmc_mode, vmc_host, listen_address,
      log_level, candump_path, balance_mode;
  std::vector<std::string> sim_args;
  int vmc_port = -1, listen_port = -1, control_port = -1;
  double vmc_rate = -1.0, rate_hz = -1.0;
  app.add_option("--config", config_path, "TOML configuration file (defaults for every key left out)");
  app.add_flag("--demo", demo, "the demo: simulated band, bundled clip, gifts on a schedule (no hardware, no file)");
  app.add_option("--seconds", seconds, "run this long, then exit (default: --demo's demo.seconds, else until Ctrl-C)");
  app.add_option("--json", json_path, "write the run's summary as JSON to FILE at exit");
  app.add_flag("--print-config", print_config, "print the effective configuration as TOML and exit");
  app.add_option("--record", record_path, "record every input to FILE, for --replay (docs/recording.md)");
  app.add_option("--replay", replay_path, "replay a recording: the same outputs, bit for bit, then exit");
  app.add_option("--speed", speed, "--replay's pace: x the recorded speed (0: as fast as it goes)")
      ->check(CLI::Range(0.0, 1000.0));
  bool hold = false, no_viewer = false;
  int viewer_port = -1;
  app.add_flag("--hold", hold, "--replay: stay at the end, paused, for the viewer to seek back (until Ctrl-C)");
  app.add_option("--viewer-port", viewer_port, "viewer.port: the live web viewer (0: any free port)");
  app.add_flag("--no-viewer", no_viewer, "viewer.enabled = false");
  std::string vrm_path;
  app.add_option("--vrm", vrm_path, "viewer.vrm: a .vrm avatar (VRoid, VSeeFace) the page drives with the pose");
  app.add_option("--band", band_source, "band.source: sim, socket, hid, can, candump, none");
  app.add_option("--band-socket", band_socket, "band.sim_socket: a tonus-band-sim serving --hid-socket PATH");
  app.add_option("--band-candump", candump_path, "band.candump_path: a candump log to replay");
  app.add_option("--sim-synthetic", sim_synthetic, "band.sim_synthetic: the simulator's scenario");
  app.add_option("--sim-arg", sim_args, "band.sim_args: an argument for the simulator (repeat)")
      ->allow_extra_args(false);
  app.add_option("--tracker", tracker_source, "tracker.source: bvh, vmc, none");
  app.add_option("--bvh", bvh_path, "tracker.bvh_path: the clip to play");
  app.add_option("--balance", balance_mode,
                 "tracker.balance: off, offline, online (the ZMP balance filter on the clip)");
  app.add_option("--vmc-mode", vmc_mode, "tracker.vmc_mode: performer, trackers");
  app.add_option("--listen-address", listen_address, "tracker.listen_address");
  app.add_option("--listen-port", listen_port, "tracker.listen_port (VMC in; 0: any free port)");
  app.add_option("--vmc-host", vmc_host, "output.host (VMC out)");
  app.add_option("--vmc-port", vmc_port, "output.port (VMC out)");
  app.add_option("--vmc-rate", vmc_rate, "output.rate_hz (1..200)");
  app.add_option("--rate-hz", rate_hz, "physics.rate_hz");
  app.add_option("--control-port", control_port, "control.port (0: any free port)");
  app.add_flag("--no-control", no_control, "control.enabled = false");
  app.add_flag("--no-realtime", no_realtime, "physics.realtime_priority = 0 and physics.lock_memory = false");
  app.add_option("--log-level", log_level, "log.level: trace, debug, info, warn, error, off");
  CLI11_PARSE(app, argc, argv);

  DaemonConfig cfg;
  std::optional<recording::Reader> replay;
  if (!replay_path.empty()) {
    // The physics must be the recording's: only the output, control and log settings may change.
    for (const auto& [set, flag] :
         {std::pair{!config_path.empty(), "--config"}, std::pair{demo, "--demo"},
          std::pair{rate_hz >= 0.0, "--rate-hz"}, std::pair{!record_path.empty(), "--record"}}) {
      if (set) {
        std::cerr << "tonusd: " << flag << " cannot go with --replay (the recording holds its configuration)\n";
        return 2;
      }
    }
    std::string error;
    replay = Daemon::open_recording(replay_path, cfg, error);
    if (!replay) {
      std::cerr << "tonusd: replay: " << error << "\n";
      return 2;
    }
    // What only looks at the run (the viewer, the control API, the logs) is this run's, not the recording's.
    const DaemonConfig defaults;
    cfg.viewer = defaults.viewer;
    cfg.control = defaults.control;
    cfg.log = defaults.log;
  }
  if (!config_path.empty()) {
    if (const std::string e = load_config(config_path, cfg); !e.empty()) {
      std::cerr << "tonusd: " << e << "\n";
      return 2;
    }
  }
  if (!band_socket.empty()) cfg.band.sim_socket = band_socket;
  if (!candump_path.empty()) cfg.band.candump_path = candump_path;
  if (!sim_synthetic.empty()) cfg.band.sim_synthetic = sim_synthetic;
  if (!sim_args.empty()) cfg.band.sim_args = sim_args;
  if (!bvh_path.empty()) cfg.tracker.bvh_path = bvh_path;
  if (!listen_address.empty()) cfg.tracker.listen_address = listen_address;
  if (listen_port >= 0) cfg.tracker.listen_port = listen_port;
  if (!vmc_host.empty()) cfg.output.host = vmc_host;
  if (vmc_port >= 0) cfg.output.port = vmc_port;
  if (vmc_rate >= 0.0) cfg.output.rate_hz = vmc_rate;
  if (rate_hz >= 0.0) cfg.physics.rate_hz = rate_hz;
  if (control_port >= 0) cfg.control.port = control_port;
  if (no_control) cfg.control.enabled = false;
  if (viewer_port >= 0) cfg.viewer.port = viewer_port;
  if (no_viewer) cfg.viewer.enabled = false;
  if (!vrm_path.empty()) cfg.viewer.vrm = vrm_path;
  if (no_realtime) {
    cfg.physics.realtime_priority = 0;
    cfg.physics.lock_memory = false;
  }
  if (!log_level.empty()) cfg.log.level = log_level;
  // The enum flags last: parse_config validates the whole config, so the paths they need are set by now.
  const struct {
    const std::string& value;
    const char* table;
    const char* key;
    const char* flag;
  } enum_flags[] = {{band_source, "band", "source", "--band"},
                    {tracker_source, "tracker", "source", "--tracker"},
                    {vmc_mode, "tracker", "vmc_mode", "--vmc-mode"},
                    {balance_mode, "tracker", "balance", "--balance"}};
  for (const auto& f : enum_flags) {
    if (f.value.empty()) continue;
    const std::string text = fmt::format("[{}]\n{} = \"{}\"\n", f.table, f.key, f.value);
    if (const std::string e = parse_config(text, f.flag, cfg); !e.empty()) {
      std::cerr << "tonusd: " << e << "\n";
      return 2;
    }
  }
  if (demo && seconds >= 0.0) cfg.demo.seconds = seconds;
  if (demo && cfg.band.source == BandSource::sim && cfg.band.sim_args.empty() && cfg.band.sim_recording.empty() &&
      cfg.band.sim_synthetic == "swell") {
    // One rise and fall of co-contraction over the demo.
    cfg.band.sim_args = {"--swell-period", fmt::format("{}", cfg.demo.seconds)};
  }
  if (const std::string e = validate(cfg); !e.empty()) {
    std::cerr << "tonusd: " << e << "\n";
    return 2;
  }
  if (const std::string e = check_files(cfg); !e.empty()) {
    std::cerr << "tonusd: " << e << "\n";
    return 2;
  }
  if (print_config) {
    std::cout << to_toml(cfg);
    return 0;
  }
  if (!record_path.empty()) {
    // Run on exactly what the recording's TOML reads back as, so a replay builds the same core.
    DaemonConfig reread;
    if (const std::string e = parse_config(to_toml(cfg), "the effective configuration", reread); !e.empty()) {
      std::cerr << "tonusd: " << e << "\n";
      return 2;
    }
    cfg = reread;
  }

  auto logger = spdlog::stderr_color_mt("tonusd");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(cfg.log.level));
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ %v");

  std::signal(SIGPIPE, SIG_IGN);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::string error;
  std::unique_ptr<Daemon> d = Daemon::create(cfg, exe_dir(), error);
  if (!d) {
    std::cerr << "tonusd: " << error << "\n";
    return 2;
  }
  if (!record_path.empty() && !d->record_to(record_path, error)) {
    std::cerr << "tonusd: " << error << "\n";
    return 1;
  }
  if (replay) {
    d->replay_from(std::move(*replay), speed);
    d->hold_replay_at_end(hold);
  }
  if (!d->start(error)) {
    std::cerr << "tonusd: " << error << "\n";
    return 1;
  }
  const double run_s = seconds >= 0.0 ? seconds : (demo ? cfg.demo.seconds : 0.0);
  d->run_for(run_s, g_stop, demo);
  d->stop();
  std::cout << d->summary_text();
  int status = 0;
  if (const ReplayDriver* r = d->replay()) {
    const ReplayStatus rs = r->status();
    switch (rs.end) {
      case ReplayEnd::finished: break;
      case ReplayEnd::truncated:
        std::cerr << "tonusd: replay: the recording ends inside a chunk (the recording daemon was stopped hard?); "
                     "replayed its "
                  << rs.chunks << " whole chunks\n";
        break;
      case ReplayEnd::running:
      case ReplayEnd::stopped: break;  // --seconds or a signal ended it
      case ReplayEnd::corrupt:
      case ReplayEnd::diverged:
        std::cerr << "tonusd: replay " << to_string(rs.end) << ": " << rs.error << "\n";
        status = 1;
        break;
    }
  }
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    out << d->summary_json().dump(2) << "\n";
    if (!out) {
      std::cerr << "tonusd: cannot write " << json_path << "\n";
      return 1;
    }
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "tonusd: " << e.what() << "\n";
    return 1;
  }
}
