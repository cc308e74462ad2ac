// A host's conversation with one band over either transport: stream messages
// in, command requests out, responses matched to their request by token.
//
// Stream policy (poll): every report goes through a SequenceTracker. A report
// newer than any before is delivered as Kind::stream; a reordered one (older
// than the newest, never seen) as Kind::late_stream, so a consumer that applies
// levels ignores it and a recorder may keep it; duplicates and reports older
// than the 64-report window are dropped. Each is counted (LinkStats), and no
// report is ever delivered twice. A device restart (new boot epoch, a CAN
// heartbeat whose uptime went back, or a backward step after a reconnect)
// restarts the numbering and marks the report `restarted`.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "tonus/host/transport/can_transport.hpp"
#include "tonus/host/transport/hid_transport.hpp"
#include "tonus/host/transport/host_clock.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/sequence.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::host {

struct LinkEvent {
  enum class Kind : std::uint8_t {
    none,          // nothing within the timeout
    stream,        // a new report
    late_stream,   // a reordered report, older than one already delivered
    response,      // a command response
    heartbeat,     // CAN heartbeat
    closed,        // the link is gone (a plain link: for good)
    disconnected,  // ReconnectingBandLink: the link dropped, reopening
    reconnected,   // ReconnectingBandLink: a link is open again
  };
  Kind kind = Kind::none;
  proto::StreamMessage stream{};
  proto::Response response{};
  proto::can::Heartbeat heartbeat{};
  std::int64_t rx_host_us = 0;  // host steady time of arrival (the kernel's receive time where known)
  bool restarted = false;       // stream: the device restarted since the previous report; heartbeat: it rebooted
};

struct LinkStats {
  std::uint64_t reports = 0;        // stream reports decoded
  std::uint64_t delivered = 0;      // as Kind::stream
  std::uint64_t late = 0;           // as Kind::late_stream (reordered)
  std::uint64_t lost = 0;           // never arrived (net of late arrivals)
  std::uint64_t duplicates = 0;     // dropped
  std::uint64_t stale = 0;          // dropped: older than the tracker's window
  std::uint64_t restarts = 0;       // device restarts seen
  std::uint64_t decode_errors = 0;  // reports, responses or frames that did not decode
  std::uint64_t disconnects = 0;    // ReconnectingBandLink: links lost (closed or stale)
  std::uint64_t reconnects = 0;     // ReconnectingBandLink: links reopened after a loss
};

class BandLink {
 public:
  using StreamSink = std::function<void(const proto::StreamMessage&)>;
  virtual ~BandLink() = default;
  virtual bool send(const proto::Request& req) = 0;
  // The next decoded event as it came off the link, without the stream policy
  // (for wrappers such as ReconnectingBandLink; most callers want poll()).
  virtual LinkEvent read_event(int timeout_ms) = 0;

  // Waits up to timeout_ms for the next event, with the stream policy applied.
  LinkEvent poll(int timeout_ms);

  // Sends `req` and waits for the response with its token; new stream reports
  // that arrive meanwhile go to `sink`. nullopt on timeout or a closed link.
  // `rx_host_us`, if given, receives the response's arrival time.
  std::optional<proto::Response> transact(const proto::Request& req, int timeout_ms, const StreamSink& sink = {},
                                          std::int64_t* rx_host_us = nullptr);

  [[nodiscard]] LinkStats stats() const;
  [[nodiscard]] std::uint64_t decode_errors() const { return total_decode_errors(); }
  [[nodiscard]] const proto::SequenceTracker& sequence() const { return tracker_; }

 protected:
  [[nodiscard]] virtual std::uint64_t total_decode_errors() const { return decode_errors_; }
  [[nodiscard]] virtual std::uint64_t disconnects() const { return 0; }
  [[nodiscard]] virtual std::uint64_t reconnects() const { return 0; }
  std::uint64_t decode_errors_ = 0;

 private:
  proto::SequenceTracker tracker_;
  bool restart_noted_ = false;
  std::uint64_t reports_ = 0;
  std::uint64_t delivered_ = 0;
  std::uint64_t late_ = 0;
};

class HidBandLink final : public BandLink {
 public:
  explicit HidBandLink(HidTransport& t) : t_(t) {}
  // Owns its transport (what ReconnectingBandLink's opener returns).
  explicit HidBandLink(std::unique_ptr<HidTransport> t) : owned_(std::move(t)), t_(*owned_) {}
  bool send(const proto::Request& req) override;
  LinkEvent read_event(int timeout_ms) override;

 private:
  std::unique_ptr<HidTransport> owned_;
  HidTransport& t_;
};

class CanBandLink final : public BandLink {
 public:
  // `id_base`: where the band's id plan sits (DeviceConfig.can_id_base; 0 = 11-bit ids).
  CanBandLink(CanTransport& t, std::uint8_t node, std::uint32_t id_base = 0)
      : t_(t),
        node_(node),
        id_base_(id_base),
        stream_(node, id_base),
        responses_(proto::can::Function::response, node, id_base) {}
  CanBandLink(std::unique_ptr<CanTransport> t, std::uint8_t node, std::uint32_t id_base = 0)
      : owned_(std::move(t)),
        t_(*owned_),
        node_(node),
        id_base_(id_base),
        stream_(node, id_base),
        responses_(proto::can::Function::response, node, id_base) {}
  bool send(const proto::Request& req) override;
  LinkEvent read_event(int timeout_ms) override;
  [[nodiscard]] const proto::can::StreamAssembler& assembler() const { return stream_; }

 private:
  std::int64_t arrival_us() const;
  std::unique_ptr<CanTransport> owned_;
  CanTransport& t_;
  std::uint8_t node_;
  std::uint32_t id_base_;
  proto::can::StreamAssembler stream_;
  proto::can::Reassembler responses_;
  // The CAN binding has no room for the boot epoch: a heartbeat whose uptime
  // went back says the band rebooted (it sends one at boot, before its first cycle).
  bool have_uptime_ = false;
  std::uint32_t last_uptime_ms_ = 0;
};

}  // namespace tonus::host
