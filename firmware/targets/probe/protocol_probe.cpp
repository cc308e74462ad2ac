// Size probe for the arm preset: exercises every protocol codec the band uses
// so the linker keeps them, then reports nothing (no I/O on a bare target).
// Built with the heap poisoned: it fails to link if the protocol allocates.
#include <array>
#include <cstdint>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/stream.hpp"

namespace {

// volatile keeps the optimiser from folding the whole program away.
volatile std::uint32_t g_sink = 0;

}  // namespace

int main() {
  using namespace tonus::proto;
  StreamMessage msg{};
  msg.sequence = static_cast<std::uint16_t>(g_sink);
  hid::Report report{};
  g_sink = g_sink + static_cast<std::uint32_t>(hid::pack_stream(msg, report));

  std::array<CanFrame, can::kMaxStreamFrames> frames{};
  std::size_t count = 0;
  g_sink = g_sink + static_cast<std::uint32_t>(can::encode_stream(msg, 1, true, frames, count));

  Request req{};
  g_sink = g_sink + static_cast<std::uint32_t>(hid::unpack_request(report, req));
  DeviceConfig cfg{};
  g_sink = g_sink + static_cast<std::uint32_t>(read_payload(req, cfg));
  g_sink = g_sink + static_cast<std::uint32_t>(check_config(cfg, 4));

  Response rsp{};
  g_sink = g_sink + static_cast<std::uint32_t>(make_response(req, Status::ok, DeviceInfo{}, rsp));
  g_sink = g_sink + static_cast<std::uint32_t>(hid::pack_response(rsp, report));

  can::Reassembler reasm(can::Function::request, 1);
  bool complete = false;
  g_sink = g_sink + static_cast<std::uint32_t>(reasm.push(frames[0], complete));
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  g_sink = g_sink + static_cast<std::uint32_t>(encode_response(rsp, buf, n));
  g_sink = g_sink +
           static_cast<std::uint32_t>(can::segment(std::span(buf).first(n), can::Function::response, 1, frames, count));
  return 0;
}
