// tonusd's band thread: owns the band link (a real band over hidapi or
// SocketCAN, the band simulator spawned or at a socket, or a candump log),
// reopens it when it drops, reads the device's identity on every connect,
// keeps the band's clock mapped onto the host's (time_sync exchanges), and
// hands every new stream report to the physics core as levels 0..1 stamped
// with its arrival and its mapped sample time. Calibration commands from the
// control API are carried out here, between reports.
#pragma once

#include <atomic>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/transport/reconnecting_link.hpp"
#include "tonus/host/transport/time_sync.hpp"

namespace tonus::daemon {

// What the band thread says, for the logger (it logs through spdlog itself:
// it is not the real-time thread).
struct BandStatus {
  bool connected = false;
  bool calibrated = false;  // the newest report says the band holds a calibration
  std::string device;       // identity line of the last device met
  host::LinkStats link;     // reports delivered, lost, late, duplicates, restarts, disconnects, ...
  bool clock_synced = false;
  double clock_offset_us = 0.0;
  double clock_drift_ppm = 0.0;
  double min_round_trip_us = 0.0;
  int sim_pid = 0;  // the spawned simulator's process id (0: none)
};

class BandInput {
 public:
  // `tools_dir`: where tonus-band-sim is looked for when band.sim_path is empty.
  BandInput(const BandConfig& config, PhysicsCore& core, std::string tools_dir);
  ~BandInput();
  BandInput(const BandInput&) = delete;
  BandInput& operator=(const BandInput&) = delete;

  void start();
  void stop();

  // A calibration phase ("rest", "mvc") or "abort", carried out by the band
  // thread; the future holds "" on success, else what went wrong.
  std::future<std::string> calibrate(const std::string& command, double duration_s = 3.0);

  [[nodiscard]] BandStatus status() const;

 private:
  struct Pending {
    std::string command;
    double duration_s = 3.0;
    std::promise<std::string> done;
  };
  void run();
  void on_connected(host::BandLink& link);
  void on_stream(const host::LinkEvent& ev);
  void serve_pending(host::BandLink& link);
  host::BandLink::StreamSink stream_sink();
  host::ReconnectingBandLink::Opener make_opener();

  BandConfig config_;
  PhysicsCore& core_;
  std::string tools_dir_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<host::ClockSync> sync_;
  std::uint8_t token_ = 1;
  mutable std::mutex mutex_;  // guards status_ and pending_
  std::atomic<bool> calibrated_{false};
  BandStatus status_;
  std::vector<std::unique_ptr<Pending>> pending_;
  struct SimChild;
  std::unique_ptr<SimChild> child_;
};

}  // namespace tonus::daemon
