// `tonus ctl`: talk to a running tonusd over its control API
// (docs/control.md). Prints the daemon's JSON reply; exit code 0 on a 2xx
// reply, 1 on an error reply, 2 when the daemon cannot be reached.
//
//   tonus ctl [--host H] [--port P] [--timeout S] status
//   tonus ctl gift ball|cube [--bone B] [--mass-kg M] [--size-m S] [--speed-mps V] [--height-m H] [--lifetime-s T]
//   tonus ctl clear
//   tonus ctl stiffness A B C D | stiffness release
//   tonus ctl calibrate rest|mvc|abort
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "tonus/host/control/api.hpp"

namespace tonus::tools {

struct CtlOptions {
  enum class Action { none, status, gift, clear, stiffness, calibrate };

  std::string host = std::string(control::kDefaultBindAddress);
  int port = control::kDefaultPort;
  double timeout_s = 2.0;

  Action action = Action::none;  // set by the parse
  control::GiftRequest gift;
  std::optional<control::Levels> levels;  // stiffness; nullopt: release
  control::CalibrationCommand calibration = control::CalibrationCommand::rest;
};

// Registers `ctl` and its subcommands on `app`, filling `opt` as they parse.
CLI::App* add_ctl_command(CLI::App& app, CtlOptions& opt);

// Sends the request the parse chose and prints the reply.
int run_ctl_command(const CtlOptions& opt);

}  // namespace tonus::tools
