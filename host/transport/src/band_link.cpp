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

std::optional<proto::Response> BandLink::transact(const proto::Request& req, int timeout_ms, const StreamSink& sink) {
  if (!send(req)) return std::nullopt;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const int left = remaining_ms(deadline);
    const LinkEvent e = poll(left);
    if (e.kind == LinkEvent::Kind::closed) return std::nullopt;
    if (e.kind == LinkEvent::Kind::stream && sink) sink(e.stream);
    if (e.kind == LinkEvent::Kind::response && e.response.token == req.token && e.response.opcode == req.opcode) {
      return e.response;
    }
    if (left == 0) return std::nullopt;
  }
}

bool HidBandLink::send(const proto::Request& req) {
  proto::hid::Report r{};
  if (proto::hid::pack_request(req, r) != proto::Error::ok) return false;
  return t_.write(r);
}

LinkEvent HidBandLink::poll(int timeout_ms) {
  LinkEvent e;
  std::array<std::uint8_t, proto::hid::kReportSize + 1> buf{};
  const int n = t_.read(buf, timeout_ms);
  if (n < 0) {
    e.kind = LinkEvent::Kind::closed;
    return e;
  }
  if (n == 0) return e;
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
  return e;
}

bool CanBandLink::send(const proto::Request& req) {
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  std::array<proto::CanFrame, proto::can::kMaxSegments> frames{};
  std::size_t count = 0;
  if (proto::encode_request(req, bytes, n) != proto::Error::ok) return false;
  if (proto::can::segment(std::span<const std::uint8_t>(bytes).first(n), proto::can::Function::request, node_, frames,
                          count) != proto::Error::ok) {
    return false;
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (!t_.write(frames[k])) return false;
  }
  return true;
}

LinkEvent CanBandLink::poll(int timeout_ms) {
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
    if (!proto::can::split_id(f.id, fn, node) || node != node_) continue;
    if (fn == proto::can::Function::heartbeat) {
      if (proto::can::decode_heartbeat(f, e.heartbeat) == proto::Error::ok) {
        e.kind = LinkEvent::Kind::heartbeat;
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
      return e;
    }
  }
}

}  // namespace tonus::host
