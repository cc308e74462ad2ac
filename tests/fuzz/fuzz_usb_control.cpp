// The USB device core's control-request parser and HID data path, fed
// arbitrary SETUP packets, OUT data stages, EP1 OUT packets, bus events and
// input reports. Never crashes; a control IN reply never exceeds the wLength
// the host asked for; an output report handed to the firmware is at most 64
// bytes; at most one IN packet per frame.
//
// Input: chunks of [kind][bytes...]; kind % 6 = 0 SETUP (8 bytes), 1 OUT data
// stage (length byte + bytes), 2 EP1 OUT packet (length byte + bytes), 3 bus
// reset, 4 suspend then resume, 5 an input report (65 bytes, then a host poll).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "tonus/usb/device_core.hpp"

using namespace tonus;

namespace {

struct FuzzDcd final : usb::Dcd {
  std::size_t last_sent = 0;
  bool loaded = false;
  bool open = false;
  void set_address(std::uint8_t a) override { TONUS_FUZZ_CHECK(a <= 127); }
  void configure_hid_endpoints(bool o) override {
    open = o;
    loaded = false;
  }
  void ep0_send(std::span<const std::uint8_t> data, bool) override {
    volatile std::uint8_t sink = 0;
    for (std::uint8_t b : data) sink = static_cast<std::uint8_t>(sink ^ b);  // every byte must be readable
    last_sent = data.size();
  }
  void ep0_receive(std::size_t length) override { TONUS_FUZZ_CHECK(length <= 64); }
  void ep0_status() override {}
  void ep0_stall() override {}
  bool hid_send(std::span<const std::uint8_t> packet) override {
    TONUS_FUZZ_CHECK(packet.size() == 64);
    if (loaded || !open) return false;
    loaded = true;
    return true;
  }
  [[nodiscard]] bool hid_busy() const override { return loaded; }
  void hid_halt(bool, bool) override {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzDcd dcd;
  usb::DeviceCore core(dcd, 0x1122334455667788ULL);
  core.on_bus_reset();
  std::size_t pos = 0;
  while (pos < size) {
    const std::uint8_t kind = data[pos++] % 6U;
    const std::size_t left = size - pos;
    if (kind == 0 && left >= 8) {
      std::array<std::uint8_t, 8> raw{};
      std::copy_n(data + pos, 8, raw.begin());
      pos += 8;
      dcd.last_sent = 0;
      core.on_setup(raw);
      const std::size_t w_length = static_cast<std::size_t>(raw[6]) | (static_cast<std::size_t>(raw[7]) << 8U);
      TONUS_FUZZ_CHECK(dcd.last_sent <= w_length);
    } else if ((kind == 1 || kind == 2) && left >= 1) {
      const std::size_t want = data[pos];
      ++pos;
      const std::size_t n = std::min(want, size - pos);
      const std::span<const std::uint8_t> bytes(data + pos, n);
      pos += n;
      if (kind == 1) {
        core.on_ep0_data(bytes);
      } else {
        core.on_hid_out(bytes);
      }
    } else if (kind == 3) {
      core.on_bus_reset();
    } else if (kind == 4) {
      core.on_suspend();
      core.on_resume();
    } else if (kind == 5 && left >= 1) {
      proto::hid::Report r{};
      const std::size_t n = std::min(r.size(), left);
      std::copy_n(data + pos, n, r.begin());
      pos += n;
      (void)core.send_input(r);
      dcd.loaded = false;  // the host's IN token of this frame
      core.service();
    }
    proto::hid::Report out{};
    std::size_t length = 0;
    while (core.receive_output(out, length)) TONUS_FUZZ_CHECK(length <= out.size());
  }
  return 0;
}
