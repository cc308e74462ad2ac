// Host side of the band's CAN link: classic frames in SocketCAN's layout.
//   SocketCanTransport    - a CAN_RAW socket bound to an interface (can0, vcan0),
//                           with error frames (bus-off) and kernel receive times
//   SeqpacketCanTransport - a Unix SOCK_SEQPACKET socket carrying the same
//                           struct can_frame, to talk to tonus-band-sim
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "tonus/protocol/can.hpp"

namespace tonus::host {

can_frame to_socketcan(const proto::CanFrame& f);
proto::CanFrame from_socketcan(const can_frame& f);

class CanTransport {
 public:
  virtual ~CanTransport() = default;
  // One frame; 1 read, 0 timeout, -1 the link is gone (see error()).
  virtual int read(proto::CanFrame& out, int timeout_ms) = 0;
  virtual bool write(const proto::CanFrame& frame) = 0;
  [[nodiscard]] virtual std::string error() const = 0;
  // Host steady time (us) at which the kernel received the last frame read; 0 if unknown.
  [[nodiscard]] virtual std::int64_t last_rx_host_us() const { return 0; }
};

// What the controller said through error frames (linux/can/error.h).
struct CanBusStatus {
  bool bus_off = false;                   // since CAN_ERR_BUSOFF, until CAN_ERR_RESTARTED
  std::uint64_t error_frames = 0;         // every error frame received
  std::uint64_t bus_off_events = 0;       // CAN_ERR_BUSOFF
  std::uint64_t restarts = 0;             // CAN_ERR_RESTARTED (the controller rejoined)
  std::uint64_t controller_problems = 0;  // CAN_ERR_CRTL: error passive/warning, overflows
  std::uint64_t tx_retries = 0;           // writes retried after ENOBUFS (the tx queue was full)
  std::uint64_t tx_dropped = 0;           // writes given up after the retries
};

class SocketCanTransport final : public CanTransport {
 public:
  // write(2) as the transport calls it; replaceable so a test can make the queue full.
  using Writer = std::function<long(int fd, const void* data, std::size_t size)>;

  // Opens a CAN_RAW socket on `iface`, receiving only the frames of `node`
  // (kernel filters on the node bits of the ID plan) and every error frame,
  // with kernel receive timestamps.
  // `id_base`: where the band's id plan sits (DeviceConfig.can_id_base; 0 = 11-bit ids).
  static std::unique_ptr<SocketCanTransport> open(const std::string& iface, std::uint8_t node, std::string& error,
                                                  std::uint32_t id_base = 0);
  // Takes a socket already bound (or any datagram socket carrying struct
  // can_frame, e.g. a socketpair in tests) and turns on receive timestamps.
  static std::unique_ptr<SocketCanTransport> adopt(int fd, std::string& error);
  ~SocketCanTransport() override;
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  // Error frames are consumed here (bus_status()), never returned.
  int read(proto::CanFrame& out, int timeout_ms) override;
  // Retries for up to ~20 ms while the kernel's queue is full (ENOBUFS).
  bool write(const proto::CanFrame& frame) override;
  [[nodiscard]] std::string error() const override { return error_; }
  [[nodiscard]] std::int64_t last_rx_host_us() const override { return last_rx_host_us_; }
  [[nodiscard]] const CanBusStatus& bus_status() const { return status_; }
  void set_writer(Writer w) { writer_ = std::move(w); }

 private:
  explicit SocketCanTransport(int fd);
  void on_error_frame(const can_frame& f);
  int fd_;
  std::string error_;
  std::int64_t last_rx_host_us_ = 0;
  CanBusStatus status_;
  Writer writer_;
};

// The CAN_RAW options open() sets, each checked: the node filter, every error
// class, receive timestamps. False with `error` naming the option that failed.
bool configure_can_socket(int fd, std::uint8_t node, std::string& error, std::uint32_t id_base = 0);
// The kernel filter passing only the band's frames: its node's ids at `id_base`.
can_filter band_filter(std::uint8_t node, std::uint32_t id_base);

class SeqpacketCanTransport final : public CanTransport {
 public:
  explicit SeqpacketCanTransport(int fd) : fd_(fd) {}
  static std::unique_ptr<SeqpacketCanTransport> connect(const std::string& path, std::string& error);
  ~SeqpacketCanTransport() override;
  SeqpacketCanTransport(const SeqpacketCanTransport&) = delete;
  SeqpacketCanTransport& operator=(const SeqpacketCanTransport&) = delete;

  int read(proto::CanFrame& out, int timeout_ms) override;
  bool write(const proto::CanFrame& frame) override;
  [[nodiscard]] std::string error() const override { return error_; }

 private:
  int fd_;
  std::string error_;
};

}  // namespace tonus::host
