// Command request/response decoders, their HID binding and every typed
// payload: never crash; accepted messages re-encode to the same bytes, and
// accepted payloads re-encode to the bytes they were read from.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus::proto;

namespace {

template <class Payload, class Message>
void check_payload(const Message& msg) {
  Payload p{};
  if (read_payload(msg, p) != Error::ok) return;
  std::array<std::uint8_t, Payload::kWireSize> out{};
  ByteWriter w(out);
  p.write(w);
  TONUS_FUZZ_CHECK(w.ok() && w.size() == Payload::kWireSize);
  // A payload of an older minor re-encodes its own bytes, then the appended
  // fields at their defaults.
  const std::size_t n = msg.length < Payload::kWireSize ? min_wire_size<Payload>() : Payload::kWireSize;
  for (std::size_t i = 0; i < n; ++i) TONUS_FUZZ_CHECK(out[i] == msg.payload[i]);
}

template <class Message>
void check_all_payloads(const Message& msg) {
  check_payload<DeviceInfo>(msg);
  check_payload<TimeSyncRequest>(msg);
  check_payload<TimeSyncResponse>(msg);
  check_payload<DeviceStats>(msg);
  check_payload<CalibrationStart>(msg);
  check_payload<CalibrationStatus>(msg);
  check_payload<DeviceConfig>(msg);
  check_payload<SetConfigResult>(msg);
  check_payload<ResetRequest>(msg);
  check_payload<FaultLog>(msg);
  DeviceConfig cfg{};
  if (read_payload(msg, cfg) == Error::ok) (void)check_config(cfg, 4);
}

template <class Message, class Decode, class Encode>
void round_trip(std::span<const std::uint8_t> in, Decode decode, Encode encode) {
  Message msg{};
  if (decode(in, msg) != Error::ok) return;
  std::array<std::uint8_t, kMaxMessageSize> out{};
  std::size_t n = 0;
  TONUS_FUZZ_CHECK(encode(msg, out, n) == Error::ok);
  TONUS_FUZZ_CHECK(n <= in.size());
  for (std::size_t i = 0; i < n; ++i) TONUS_FUZZ_CHECK(out[i] == in[i]);
  check_all_payloads(msg);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  round_trip<Request>(in, decode_request, encode_request);
  round_trip<Response>(in, decode_response, encode_response);
  Request req{};
  (void)hid::unpack_request(in, req);
  Response rsp{};
  (void)hid::unpack_response(in, rsp);
  return 0;
}
