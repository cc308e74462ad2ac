// CAN side: the input is a node byte, then frames of 12 bytes each (id u16
// LE, dlc, flags, 8 data bytes) fed to the stream
// assembler, the segment reassembler and the heartbeat decoder. Never crash;
// every delivered stream message is valid and every reassembled message is
// at most one HID payload long.
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"

using namespace tonus::proto;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const auto node = static_cast<std::uint8_t>(data[0] & can::kNodeMask);
  can::StreamAssembler stream(node);
  can::Reassembler requests(can::Function::request, node);
  can::Reassembler responses(can::Function::response, node);
  constexpr std::size_t kFrameBytes = 12;
  for (std::size_t pos = 1; pos + kFrameBytes <= size; pos += kFrameBytes) {
    CanFrame f{};
    f.id = static_cast<std::uint32_t>(data[pos] | (data[pos + 1] << 8U)) & 0x7FFU;
    f.dlc = data[pos + 2];  // may exceed 8: every decoder must refuse it
    f.flags = static_cast<std::uint8_t>(data[pos + 3] & 0x07U);
    for (std::size_t i = 0; i < 8; ++i) f.data[i] = data[pos + 4 + i];
    bool complete = false;
    if (stream.push(f, complete) == Error::ok && complete) {
      TONUS_FUZZ_CHECK(validate(stream.message()) == Error::ok);
    }
    if (requests.push(f, complete) == Error::ok && complete) {
      TONUS_FUZZ_CHECK(requests.message().size() <= can::kMaxSegments * can::kSegmentData);
      Request req{};
      (void)decode_request(requests.message(), req);
    }
    if (responses.push(f, complete) == Error::ok && complete) {
      Response rsp{};
      (void)decode_response(responses.message(), rsp);
    }
    can::Heartbeat hb{};
    (void)can::decode_heartbeat(f, hb);
  }
  return 0;
}
