#include "tonus/host/daemon/candump_replay.hpp"

#include <fstream>
#include <thread>

#include "tonus/host/transport/host_clock.hpp"

namespace tonus::daemon {

std::unique_ptr<CandumpReplay> CandumpReplay::open(const std::string& path, bool loop, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot open the candump log";
    return nullptr;
  }
  auto r = std::unique_ptr<CandumpReplay>(new CandumpReplay());
  r->loop_ = loop;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    proto::candump::Record rec{};
    if (proto::candump::parse(line, rec) != proto::Error::ok) {
      ++r->bad_lines_;
      continue;
    }
    // Time must not run backwards within a replay: such a line is out of order.
    if (!r->records_.empty() && rec.time_us < r->records_.back().time_us) {
      ++r->bad_lines_;
      continue;
    }
    r->records_.push_back(rec);
  }
  if (r->records_.empty()) {
    error = path + ": no CAN frame in the candump log";
    return nullptr;
  }
  return r;
}

int CandumpReplay::read(proto::CanFrame& out, int timeout_ms) {
  if (!started_) {
    start_ = Clock::now();
    started_ = true;
  }
  if (next_ >= records_.size()) {
    if (!loop_) {
      error_ = "end of the candump log";
      return -1;
    }
    next_ = 0;
    start_ = Clock::now();
  }
  const proto::candump::Record& rec = records_[next_];
  const auto due = start_ + std::chrono::microseconds(rec.time_us - records_.front().time_us);
  const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  if (due > deadline) {
    std::this_thread::sleep_until(deadline);
    return 0;
  }
  std::this_thread::sleep_until(due);
  out = rec.frame;
  last_rx_us_ = host::steady_now_us();
  ++next_;
  return 1;
}

}  // namespace tonus::daemon
