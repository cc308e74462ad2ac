// `tonus demo`: a simulated band stream pushed through the HID and CAN
// bindings over lossy links and decoded back, with a readable summary.
#pragma once

#include <cstdint>
#include <string>

namespace tonus::tools {

struct DemoOptions {
  double seconds = 5.0;
  unsigned report_rate_hz = 1000;
  double loss = 0.01;          // probability a report / frame is dropped
  double duplication = 0.002;  // probability a report is sent twice
  double reorder = 0.002;      // probability two neighbouring reports swap
  std::uint64_t seed = 1;
  std::uint8_t can_node = 1;
  unsigned can_envelope_divider = 10;
  std::string candump_path;  // empty: no log
};

// Returns the process exit code: 0 when every delivered message decoded to
// exactly what was sent and every counter matched what the links injected.
int run_protocol_demo(const DemoOptions& opt);

}  // namespace tonus::tools
