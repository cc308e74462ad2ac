// The device's command path: fw::Device fed arbitrary HID output reports and
// CAN frames between sample blocks. Never crashes; every input report it sends
// decodes (a stream report or a response); the configuration in use always
// passes the device's own check.
//
// Input: chunks of [kind][length][bytes...]; kind % 3 = 0 a HID output report,
// 1 a CAN frame (id lo, id hi, data...), 2 a 1 ms sample block.
#include <cstddef>
#include <cstdint>
#include <span>

#include "fake_board.hpp"
#include "fuzz_check.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/protocol/hid.hpp"

using namespace tonus;

namespace {

// Every input report the device sent decodes (a stream report or a response).
void check_sent(test::QueueHid& hid, test::QueueCan& can) {
  for (const proto::hid::Report& r : hid.sent) {
    proto::StreamMessage m{};
    proto::Response rsp{};
    const bool ok = (r[0] == proto::hid::kReportIdStream && proto::hid::unpack_stream(r, m) == proto::Error::ok) ||
                    (r[0] == proto::hid::kReportIdResponse && proto::hid::unpack_response(r, rsp) == proto::Error::ok);
    TONUS_FUZZ_CHECK(ok);
  }
  for (const proto::CanFrame& f : can.sent) TONUS_FUZZ_CHECK(f.dlc <= 8);
  hid.sent.clear();
  can.sent.clear();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  test::ManualSampler sampler(fw::FrontEnd{});
  sim::SimClock clock(false);
  sim::FlashStorage storage;
  sim::SimLed led;
  sim::SimWatchdog watchdog;
  sim::SimSystem system;
  test::QueueHid hid;
  test::QueueCan can;
  hal::Board board{sampler, clock, storage, led, watchdog, system, &hid, &can, 7, 1};
  fw::Device dev(board);
  dev.boot();
  check_sent(hid, can);
  std::uint64_t t_us = 0;
  std::uint32_t sequence = 0;
  std::size_t pos = 0;
  while (pos + 2 <= size) {
    const std::uint8_t kind = data[pos] % 3U;
    const std::size_t n = data[pos + 1];
    pos += 2;
    const std::span<const std::uint8_t> bytes(data + pos, n < size - pos ? n : size - pos);
    pos += bytes.size();
    if (kind == 0) {
      hid.inbox.emplace_back(bytes.begin(), bytes.end());
    } else if (kind == 1 && bytes.size() >= 2) {
      proto::CanFrame f{};
      f.id = static_cast<std::uint32_t>(bytes[0] | ((bytes[1] & 0x07U) << 8U));
      f.dlc = static_cast<std::uint8_t>(bytes.size() - 2 < 8 ? bytes.size() - 2 : 8);
      for (std::size_t k = 0; k < f.dlc; ++k) f.data[k] = bytes[2 + k];
      can.inbox.push_back(f);
    } else {
      // A 1 ms block at the sample rate in use, the samples from the input.
      const std::uint16_t rate = dev.config().sample_rate_hz;
      hal::SampleBlock block{};
      block.frames = static_cast<std::uint16_t>(rate / 1000U == 0 ? 1 : rate / 1000U);
      block.sequence = sequence++;
      block.first_sample_us = t_us;
      for (std::size_t k = 0; k < bytes.size() && k < block.samples.size(); ++k) {
        block.samples[k] = static_cast<std::int16_t>(bytes[k] * 16);
      }
      sampler.push(block);
    }
    t_us += 1000;
    clock.advance_to(t_us);
    dev.poll();
    if (system.take_reset()) dev.boot();
    check_sent(hid, can);
    TONUS_FUZZ_CHECK(fw::check_device_config(dev.config(), sampler.front_end()) == proto::ConfigField::none);
  }
  return 0;
}
