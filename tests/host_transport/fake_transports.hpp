// Scripted transports for the link tests: reports or frames handed out in the
// order a test chose (with loss, duplicates, reordering), then "unplugged".
#pragma once

#include <cstdint>
#include <cstring>
#include <deque>
#include <span>
#include <string>
#include <vector>

#include "tonus/host/transport/band_link.hpp"
#include "tonus/protocol/hid.hpp"

namespace tonus::test {

inline proto::StreamMessage report(std::uint16_t seq, std::uint8_t epoch) {
  proto::StreamMessage m{};
  m.sequence = seq;
  m.boot_epoch = epoch;
  m.device_time_us = static_cast<std::uint32_t>(seq) * 1000U;
  m.levels[0] = seq;  // the payload names the report, to check what was delivered
  return m;
}

class FakeHidTransport final : public host::HidTransport {
 public:
  std::deque<std::vector<std::uint8_t>> inbox;
  std::vector<std::vector<std::uint8_t>> sent;
  bool gone_when_empty = true;

  void push(const proto::StreamMessage& m) {
    proto::hid::Report r{};
    if (proto::hid::pack_stream(m, r) == proto::Error::ok) inbox.emplace_back(r.begin(), r.end());
  }
  int read(std::span<std::uint8_t> out, int) override {
    if (inbox.empty()) return gone_when_empty ? -1 : 0;
    const std::vector<std::uint8_t> r = inbox.front();
    inbox.pop_front();
    const std::size_t n = r.size() < out.size() ? r.size() : out.size();
    if (n != 0) std::memcpy(out.data(), r.data(), n);  // an empty report has no data pointer
    return static_cast<int>(n);
  }
  bool write(std::span<const std::uint8_t> report) override {
    sent.emplace_back(report.begin(), report.end());
    return true;
  }
  [[nodiscard]] std::string error() const override { return "unplugged"; }
};

class FakeCanTransport final : public host::CanTransport {
 public:
  std::deque<proto::CanFrame> inbox;
  int read(proto::CanFrame& out, int) override {
    if (inbox.empty()) return -1;
    out = inbox.front();
    inbox.pop_front();
    return 1;
  }
  bool write(const proto::CanFrame&) override { return true; }
  [[nodiscard]] std::string error() const override { return "unplugged"; }
};

}  // namespace tonus::test
