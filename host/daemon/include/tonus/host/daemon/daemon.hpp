// tonusd, wired: the humanoid, the physics core on its paced thread, the band
// and tracker input threads, the VMC output thread; the caller's thread runs
// the supervisor loop (run_for): it schedules the demo's gifts, drains the
// physics thread's events into the log and the summary, and prints the
// periodic status line. The control API (host/control) calls the command
// methods from its own threads.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tonus/host/control/server.hpp"
#include "tonus/host/daemon/band_input.hpp"
#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/control_handler.hpp"
#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/daemon/physics_thread.hpp"
#include "tonus/host/daemon/recorder.hpp"
#include "tonus/host/daemon/replay.hpp"
#include "tonus/host/daemon/tracker_input.hpp"
#include "tonus/host/daemon/viewer_feed.hpp"
#include "tonus/host/daemon/vmc_output.hpp"

namespace tonus::daemon {

struct GiftRecord {
  std::uint32_t id = 0;
  std::string kind;
  std::string bone;
  double at_s = 0.0;        // physics time it appeared
  double stiffness = 0.0;   // its bone group's applied stiffness then
  double natural_hz = 0.0;  // ... and that group's drive frequency (the weak gains)
  double peak_deflection_m = 0.0;
  bool measured = false;  // the reaction window closed
  std::string refused;    // why it was refused (empty: it appeared)
};

struct StiffnessPoint {
  double t_s = 0.0;
  Levels levels{};
};

class Daemon {
 public:
  // Builds the humanoid and the physics core; nullptr and `error` when the
  // config does not hold. `tools_dir`: where tonus-band-sim lives.
  static std::unique_ptr<Daemon> create(const DaemonConfig& config, std::string tools_dir, std::string& error);
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  // Recording (before start): every input the physics consumes goes to
  // `path` (docs/recording.md). The config must be one that reads back from
  // its own TOML to the same values (tonusd passes it through to_toml and
  // parse_config first), so a replay builds the very same core.
  bool record_to(const std::string& path, std::string& error);

  // Replay: the configuration a recording was made with (command-line
  // overrides may go on top, then create()), and the reader past its header.
  static std::optional<recording::Reader> open_recording(const std::string& path, DaemonConfig& config,
                                                         std::string& error);
  // Before start: replay `reader` instead of running the inputs and the
  // paced physics thread; `speed` x the recorded pace (0: as fast as it goes).
  void replay_from(recording::Reader reader, double speed);
  [[nodiscard]] const ReplayDriver* replay() const { return replay_.get(); }
  void hold_replay_at_end(bool hold) {
    if (replay_) replay_->hold_at_end(hold);
  }

  // Starts every thread; false and `error` (nothing left running) when an
  // input or output cannot be opened.
  bool start(std::string& error);
  // Supervises for `seconds` (0: until `stop_flag`), then returns.
  void run_for(double seconds, const std::atomic<bool>& stop_flag, bool demo_gifts);
  void stop();

  // Commands (any thread). The id is echoed in events and the summary.
  std::uint32_t spawn_gift(GiftKind kind, sim::Bone bone, const avatar::ThrowBall* ball, const avatar::DropCube* cube,
                           std::string& error);
  bool clear_gifts();
  bool set_stiffness_override(const std::optional<Levels>& levels);
  std::future<std::string> calibrate(const std::string& command);

  [[nodiscard]] nlohmann::json status_json() const;
  // After stop(): the run's figures (tonusd --json).
  [[nodiscard]] nlohmann::json summary_json() const;
  // After stop(): the human-readable summary.
  [[nodiscard]] std::string summary_text() const;

  [[nodiscard]] int vmc_listen_port() const { return tracker_ ? tracker_->vmc_port() : 0; }
  [[nodiscard]] int control_port() const { return control_server_ ? control_server_->port() : 0; }
  [[nodiscard]] int viewer_port() const { return viewer_ ? viewer_->port() : 0; }
  [[nodiscard]] const DaemonConfig& config() const { return config_; }

 private:
  Daemon() = default;
  void drain_events();
  void log_status();
  bool start_viewer(std::string& error);
  void viewer_extras(viewer::Frame& frame);

  DaemonConfig config_;
  std::unique_ptr<sim::Model> model_;
  std::unique_ptr<PhysicsCore> core_;
  std::unique_ptr<PhysicsThread> physics_;
  std::unique_ptr<BandInput> band_;
  std::unique_ptr<TrackerInput> tracker_;
  std::unique_ptr<VmcOutput> output_;
  std::unique_ptr<DaemonControl> control_;
  std::unique_ptr<control::ControlServer> control_server_;
  std::unique_ptr<Recorder> recorder_;
  std::string record_path_;
  std::unique_ptr<ReplayDriver> replay_;
  std::unique_ptr<ViewerFeed> viewer_;
  IntervalFigures last_interval_;  // guarded by mutex_
  std::atomic<std::uint32_t> next_id_{1};
  double started_wall_s_ = 0.0;
  double run_seconds_ = 0.0;
  double cpu_seconds_ = 0.0;
  mutable std::mutex mutex_;  // guards the records below (status_json reads them from the control threads)
  std::vector<GiftRecord> gifts_;
  std::vector<StiffnessPoint> trace_;
  Snapshot last_;  // the newest status snapshot
  std::uint64_t events_seen_ = 0;
};

}  // namespace tonus::daemon
