// Stream decoder and its HID binding: never crash; whatever decodes must
// re-encode to the same bytes (up to the message's own length).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus::proto;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  StreamMessage msg{};
  if (decode_stream(in, msg) == Error::ok) {
    std::array<std::uint8_t, kMaxMessageSize> out{};
    std::size_t n = 0;
    TONUS_FUZZ_CHECK(encode_stream(msg, out, n) == Error::ok);
    TONUS_FUZZ_CHECK(n <= size);
    for (std::size_t i = 0; i < n; ++i) TONUS_FUZZ_CHECK(out[i] == data[i]);  // byte 3 too: the boot epoch
  }
  StreamMessage from_report{};
  if (hid::unpack_stream(in, from_report) == Error::ok) {
    TONUS_FUZZ_CHECK(size >= 1 && data[0] == hid::kReportIdStream && size <= hid::kReportSize);
    StreamMessage direct{};
    TONUS_FUZZ_CHECK(decode_stream(in.subspan(1), direct) == Error::ok && direct == from_report);
  }
  return 0;
}
