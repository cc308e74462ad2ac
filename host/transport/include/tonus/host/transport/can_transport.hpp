// Host side of the band's CAN link: classic frames in SocketCAN's layout.
//   SocketCanTransport    - a CAN_RAW socket bound to an interface (can0, vcan0)
//   SeqpacketCanTransport - a Unix SOCK_SEQPACKET socket carrying the same
//                           struct can_frame, to talk to tonus-band-sim
#pragma once

#include <linux/can.h>

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
};

class SocketCanTransport final : public CanTransport {
 public:
  // Opens a CAN_RAW socket on `iface`, receiving only the frames of `node`
  // (kernel filters on the node bits of the ID plan).
  static std::unique_ptr<SocketCanTransport> open(const std::string& iface, std::uint8_t node, std::string& error);
  ~SocketCanTransport() override;
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  int read(proto::CanFrame& out, int timeout_ms) override;
  bool write(const proto::CanFrame& frame) override;
  [[nodiscard]] std::string error() const override { return error_; }

 private:
  explicit SocketCanTransport(int fd) : fd_(fd) {}
  int fd_;
  std::string error_;
};

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
