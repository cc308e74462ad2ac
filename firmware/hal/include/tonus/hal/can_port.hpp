// HAL: one classic CAN port (bxCAN on the band). Frames use the protocol's
// transport-neutral CanFrame; the driver maps it to its mailboxes.
#pragma once

#include "tonus/protocol/can.hpp"

namespace tonus::hal {

class CanPort {
 public:
  // Queues a frame; false when the transmit queue is full (the frame is dropped).
  virtual bool send(const proto::CanFrame& frame) = 0;
  // Takes one received frame; false if none.
  virtual bool receive(proto::CanFrame& frame) = 0;
  // Every queued frame has left (the transmit queue and mailboxes are empty).
  [[nodiscard]] virtual bool idle() const = 0;

 protected:
  ~CanPort() = default;
};

}  // namespace tonus::hal
