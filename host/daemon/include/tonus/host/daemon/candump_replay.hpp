// A candump log (can-utils' `candump -l` format) replayed as a CAN link, at
// the pace of its own timestamps, so a recorded band session drives tonusd as
// the band did. Lines that do not parse are skipped and counted; the end of
// the log is the end of the link (or, looping, the log starts again).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tonus/host/transport/can_transport.hpp"
#include "tonus/protocol/candump.hpp"

namespace tonus::daemon {

class CandumpReplay final : public host::CanTransport {
 public:
  // nullptr and `error` when the file cannot be read or holds no frame.
  static std::unique_ptr<CandumpReplay> open(const std::string& path, bool loop, std::string& error);

  int read(proto::CanFrame& out, int timeout_ms) override;
  bool write(const proto::CanFrame&) override { return true; }  // a recording does not listen
  [[nodiscard]] std::string error() const override { return error_; }
  [[nodiscard]] std::int64_t last_rx_host_us() const override { return last_rx_us_; }

  [[nodiscard]] std::size_t frames() const { return records_.size(); }
  [[nodiscard]] std::size_t bad_lines() const { return bad_lines_; }

 private:
  using Clock = std::chrono::steady_clock;
  std::vector<proto::candump::Record> records_;
  std::size_t next_ = 0;
  std::size_t bad_lines_ = 0;
  bool loop_ = false;
  Clock::time_point start_{};
  bool started_ = false;
  std::string error_;
  std::int64_t last_rx_us_ = 0;
};

}  // namespace tonus::daemon
