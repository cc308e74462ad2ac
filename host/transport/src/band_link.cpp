#include "tonus/host/transport/band_link.hpp"

#include <array>

#include "tonus/protocol/hid.hpp"

namespace tonus::host {

namespace {

int remaining_ms(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
  return left.count() > 0 ? static_cast<int>(left.count()) : 0;
}

}  // namespace

LinkEvent BandLink::poll(int timeout_ms) {
  using Verdict = proto::SequenceTracker::Verdict;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    LinkEvent e = read_event(remaining_ms(deadline));
    if (e.kind == LinkEvent::Kind::heartbeat && e.restarted) {
      tracker_.note_restart();
      restart_noted_ = true;
    }
    if (e.kind == LinkEvent::Kind::reconnected) tracker_.note_reconnect();
    if (e.kind != LinkEvent::Kind::stream) return e;
    ++reports_;
    const Verdict v = tracker_.push(e.stream.sequence, e.stream.boot_epoch);
    const bool noted = restart_noted_;
    restart_noted_ = false;
    switch (v) {
      case Verdict::first:
      case Verdict::in_order:
      case Verdict::gap:
      case Verdict::resync:
        e.restarted = v == Verdict::resync || (v == Verdict::first && noted);
        ++delivered_;
        return e;
      case Verdict::late:
        e.kind = LinkEvent::Kind::late_stream;
        ++late_;
        return e;
      case Verdict::duplicate:
      case Verdict::stale: break;  // counted by the tracker, never delivered
    }
    if (remaining_ms(deadline) == 0) return LinkEvent{};
  }
}

std::optional<proto::Response> BandLink::transact(const proto::Request& req, int timeout_ms, const StreamSink& sink,
                                                  std::int64_t* rx_host_us) {
  if (!send(req)) return std::nullopt;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const int left = remaining_ms(deadline);
    const LinkEvent e = poll(left);
    if (e.kind == LinkEvent::Kind::closed || e.kind == LinkEvent::Kind::disconnected) return std::nullopt;
    if (e.kind == LinkEvent::Kind::stream && sink) sink(e.stream);
    if (e.kind == LinkEvent::Kind::response && e.response.token == req.token && e.response.opcode == req.opcode) {
      if (rx_host_us != nullptr) *rx_host_us = e.rx_host_us;
      return e.response;
    }
    if (left == 0) return std::nullopt;
  }
}

LinkStats BandLink::stats() const {
  LinkStats s;
  s.reports = reports_;
  s.delivered = delivered_;
  s.late = late_;
  s.lost = tracker_.lost();
  s.duplicates = tracker_.duplicates();
  s.stale = tracker_.stale();
  s.restarts = tracker_.resyncs();
  s.decode_errors = total_decode_errors();
  s.disconnects = disconnects();
  s.reconnects = reconnects();
  return s;
}

bool HidBandLink::send(const proto::Request& req) {
  proto::hid::Report r{};
  if (proto::hid::pack_request(req, r) != proto::Error::ok) return false;
  return t_.write(r);
}

LinkEvent HidBandLink::read_event(int timeout_ms) {
  LinkEvent e;
  std::array<std::uint8_t, proto::hid::kReportSize + 1> buf{};
  const int n = t_.read(buf, timeout_ms);
  if (n < 0) {
    e.kind = LinkEvent::Kind::closed;
    return e;
  }
  if (n == 0) return e;
  e.rx_host_us = steady_now_us();
  const auto report = std::span<const std::uint8_t>(buf).first(static_cast<std::size_t>(n));
  if (buf[0] == proto::hid::kReportIdStream) {
    if (proto::hid::unpack_stream(report, e.stream) == proto::Error::ok) {
      e.kind = LinkEvent::Kind::stream;
      return e;
    }
  } else if (buf[0] == proto::hid::kReportIdResponse) {
    if (proto::hid::unpack_response(report, e.response) == proto::Error::ok) {
      e.kind = LinkEvent::Kind::response;
      return e;
    }
  }
  ++decode_errors_;
  e.rx_host_us = 0;
  return e;
}

bool CanBandLink::send(const proto::Request& req) {
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  std::array<proto::CanFrame, proto::can::kMaxSegments> frames{};
  std::size_t count = 0;
  if (proto::encode_request(req, bytes, n) != proto::Error::ok) return false;
  if (proto::can::segment(std::span<const std::uint8_t>(bytes).first(n), proto::can::Function::request, node_, frames,
                          count, id_base_) != proto::Error::ok) {
    return false;
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (!t_.write(frames[k])) return false;
  }
  return true;
}

std::int64_t CanBandLink::arrival_us() const {
  const std::int64_t kernel = t_.last_rx_host_us();
  return kernel != 0 ? kernel : steady_now_us();
}

LinkEvent CanBandLink::read_event(int timeout_ms) {
  LinkEvent e;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    proto::CanFrame f{};
    const int r = t_.read(f, remaining_ms(deadline));
    if (r < 0) {
      e.kind = LinkEvent::Kind::closed;
      return e;
    }
    if (r == 0) return e;
    proto::can::Function fn{};
    std::uint8_t node = 0;
    if (!proto::can::split_frame(f, id_base_, fn, node) || node != node_) continue;
    if (fn == proto::can::Function::heartbeat) {
      if (proto::can::decode_heartbeat(f, e.heartbeat, id_base_) == proto::Error::ok) {
        // Back by less than half the u32 range: a reboot, not the 49.7-day wrap.
        const std::uint32_t back = last_uptime_ms_ - e.heartbeat.uptime_ms;
        e.restarted = have_uptime_ && e.heartbeat.uptime_ms < last_uptime_ms_ && back < 0x80000000U;
        have_uptime_ = true;
        last_uptime_ms_ = e.heartbeat.uptime_ms;
        e.kind = LinkEvent::Kind::heartbeat;
        e.rx_host_us = arrival_us();
        return e;
      }
      ++decode_errors_;
      continue;
    }
    if (fn == proto::can::Function::response) {
      bool complete = false;
      if (responses_.push(f, complete) != proto::Error::ok) {
        ++decode_errors_;
        continue;
      }
      if (!complete) continue;
      if (proto::decode_response(responses_.message(), e.response) == proto::Error::ok) {
        e.kind = LinkEvent::Kind::response;
        e.rx_host_us = arrival_us();
        return e;
      }
      ++decode_errors_;
      continue;
    }
    bool complete = false;
    if (stream_.push(f, complete) != proto::Error::ok) {
      ++decode_errors_;
      continue;
    }
    if (complete) {
      e.kind = LinkEvent::Kind::stream;
      e.stream = stream_.message();
      e.rx_host_us = arrival_us();
      return e;
    }
  }
}

}  // namespace tonus::host
