// The device's command path: fw::Device fed arbitrary HID output reports and
// CAN frames between sample blocks. Never crashes; every input report it sends
// decodes (a stream report or a response); the configuration in use always
// passes the device's own check.
//
// Input: chunks of [kind][length][bytes...]; kind % 3 = 0 a HID output report,
// 1 a CAN frame (id lo, id hi, data...), 2 a 1 ms sample block.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "sim_hal.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/protocol/hid.hpp"

using namespace tonus;

namespace {

class FuzzHid final : public hal::UsbHid {
 public:
  [[nodiscard]] bool connected() const override { return true; }
  bool send_input(const proto::hid::Report& r) override {
    proto::StreamMessage m{};
    proto::Response rsp{};
    const bool ok = (r[0] == proto::hid::kReportIdStream && proto::hid::unpack_stream(r, m) == proto::Error::ok) ||
                    (r[0] == proto::hid::kReportIdResponse && proto::hid::unpack_response(r, rsp) == proto::Error::ok);
    TONUS_FUZZ_CHECK(ok);
    return true;
  }
  void service() override {}
  [[nodiscard]] bool idle() const override { return true; }
  bool receive_output(proto::hid::Report& r, std::size_t& length) override {
    if (inbox.empty()) return false;
    r.fill(0);
    const auto& bytes = inbox.front();
    length = bytes.size();
    for (std::size_t k = 0; k < bytes.size() && k < r.size(); ++k) r[k] = bytes[k];
    inbox.pop_front();
    return true;
  }
  std::deque<std::vector<std::uint8_t>> inbox;
};

class FuzzCan final : public hal::CanPort {
 public:
  bool send(const proto::CanFrame& f) override {
    TONUS_FUZZ_CHECK(f.dlc <= 8);
    return true;
  }
  bool receive(proto::CanFrame& f) override {
    if (inbox.empty()) return false;
    f = inbox.front();
    inbox.pop_front();
    return true;
  }
  [[nodiscard]] bool idle() const override { return true; }
  std::deque<proto::CanFrame> inbox;
};

class FuzzSampler final : public hal::EmgSampler {
 public:
  [[nodiscard]] fw::FrontEnd front_end() const override { return fw::FrontEnd{}; }
  bool start(std::uint16_t rate_hz) override { return front_end().supports_rate(rate_hz); }
  const hal::SampleBlock* acquire() override { return pending ? &block : nullptr; }
  void release() override { pending = false; }
  hal::SampleBlock block{};
  bool pending = false;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzSampler sampler;
  sim::SimClock clock(false);
  sim::FlashStorage storage;
  sim::SimLed led;
  sim::SimWatchdog watchdog;
  sim::SimSystem system;
  FuzzHid hid;
  FuzzCan can;
  hal::Board board{sampler, clock, storage, led, watchdog, system, &hid, &can, 7, 1};
  fw::Device dev(board);
  dev.boot();
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
      sampler.block = hal::SampleBlock{};
      sampler.block.frames = static_cast<std::uint16_t>(rate / 1000U == 0 ? 1 : rate / 1000U);
      sampler.block.sequence = sequence++;
      sampler.block.first_sample_us = t_us;
      for (std::size_t k = 0; k < bytes.size() && k < sampler.block.samples.size(); ++k) {
        sampler.block.samples[k] = static_cast<std::int16_t>(bytes[k] * 16);
      }
      sampler.pending = true;
    }
    t_us += 1000;
    clock.advance_to(t_us);
    dev.poll();
    if (system.take_reset()) dev.boot();
    TONUS_FUZZ_CHECK(fw::check_device_config(dev.config(), sampler.front_end()) == proto::ConfigField::none);
  }
  return 0;
}
