// The control API's requests (host/control, docs/control.md) carried out on a
// Daemon: gifts and overrides become commands on the physics thread's queue,
// calibration goes to the band thread, status reads the daemon's counters.
// Runs on the control server's threads and on the viewer's, concurrently:
// every call is safe so (the command queue serialises its producers, the
// band's pending calibrations and the daemon's records have their mutexes).
// Nothing here blocks for long (a calibration waits at most for the band's
// answer, 1 s).
#pragma once

#include "tonus/host/control/api.hpp"

namespace tonus::daemon {

class Daemon;

class DaemonControl final : public control::Handler {
 public:
  explicit DaemonControl(Daemon& daemon) : daemon_(daemon) {}

  control::Reply spawn_gift(const control::GiftRequest& request) override;
  control::Reply clear_gifts() override;
  control::Reply set_stiffness_override(const std::optional<control::Levels>& levels) override;
  control::Reply calibrate(control::CalibrationCommand command) override;
  control::Reply status() override;

 private:
  Daemon& daemon_;
};

}  // namespace tonus::daemon
