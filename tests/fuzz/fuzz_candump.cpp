// candump log lines: never crash; an accepted line formats back to a line
// that parses to the same record.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "tonus/protocol/candump.hpp"

using namespace tonus::proto;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  candump::Record rec{};
  if (candump::parse(line, rec) != Error::ok) return 0;
  std::array<char, candump::kMaxLine> out{};
  std::size_t n = 0;
  TONUS_FUZZ_CHECK(candump::format(rec, out, n) == Error::ok);
  candump::Record again{};
  TONUS_FUZZ_CHECK(candump::parse(std::string_view(out.data(), n), again) == Error::ok);
  TONUS_FUZZ_CHECK(again == rec);
  return 0;
}
