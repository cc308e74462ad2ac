// A host's conversation with one band over either transport: stream messages
// in, command requests out, responses matched to their request by token.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>

#include "tonus/host/transport/can_transport.hpp"
#include "tonus/host/transport/hid_transport.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::host {

struct LinkEvent {
  enum class Kind : std::uint8_t { none, stream, response, heartbeat, closed };
  Kind kind = Kind::none;
  proto::StreamMessage stream{};
  proto::Response response{};
  proto::can::Heartbeat heartbeat{};
};

class BandLink {
 public:
  using StreamSink = std::function<void(const proto::StreamMessage&)>;
  virtual ~BandLink() = default;
  virtual bool send(const proto::Request& req) = 0;
  // Waits up to timeout_ms for the next decoded event.
  virtual LinkEvent poll(int timeout_ms) = 0;

  // Sends `req` and waits for the response with its token; stream messages
  // that arrive meanwhile go to `sink`. nullopt on timeout or a closed link.
  std::optional<proto::Response> transact(const proto::Request& req, int timeout_ms, const StreamSink& sink = {});

  [[nodiscard]] std::uint64_t decode_errors() const { return decode_errors_; }

 protected:
  std::uint64_t decode_errors_ = 0;
};

class HidBandLink final : public BandLink {
 public:
  explicit HidBandLink(HidTransport& t) : t_(t) {}
  bool send(const proto::Request& req) override;
  LinkEvent poll(int timeout_ms) override;

 private:
  HidTransport& t_;
};

class CanBandLink final : public BandLink {
 public:
  CanBandLink(CanTransport& t, std::uint8_t node)
      : t_(t), node_(node), stream_(node), responses_(proto::can::Function::response, node) {}
  bool send(const proto::Request& req) override;
  LinkEvent poll(int timeout_ms) override;
  [[nodiscard]] const proto::can::StreamAssembler& assembler() const { return stream_; }

 private:
  CanTransport& t_;
  std::uint8_t node_;
  proto::can::StreamAssembler stream_;
  proto::can::Reassembler responses_;
};

}  // namespace tonus::host
