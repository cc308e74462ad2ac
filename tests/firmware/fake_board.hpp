// In-process board for device tests: the simulator's clock, storage, LED,
// watchdog and reset, plus queue-backed HID and CAN ports and a sampler the
// test feeds block by block (with any sequence number it likes).
#pragma once

#include <deque>
#include <functional>
#include <vector>

#include "sim_hal.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/synthetic.hpp"

namespace tonus::test {

class QueueHid final : public hal::UsbHid {
 public:
  [[nodiscard]] bool connected() const override { return true; }
  bool send_input(const proto::hid::Report& r) override {
    sent.push_back(r);
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
  std::vector<proto::hid::Report> sent;
};

class QueueCan final : public hal::CanPort {
 public:
  bool send(const proto::CanFrame& f) override {
    sent.push_back(f);
    return true;
  }
  [[nodiscard]] bool idle() const override { return true; }
  bool receive(proto::CanFrame& f) override {
    if (inbox.empty()) return false;
    f = inbox.front();
    inbox.pop_front();
    return true;
  }
  std::deque<proto::CanFrame> inbox;
  std::vector<proto::CanFrame> sent;
};

class ManualSampler final : public hal::EmgSampler {
 public:
  explicit ManualSampler(fw::FrontEnd fe) : fe_(fe) {}
  [[nodiscard]] fw::FrontEnd front_end() const override { return fe_; }
  bool start(std::uint16_t rate_hz) override {
    rate_hz_ = rate_hz;
    ++starts_;
    return fe_.supports_rate(rate_hz);
  }
  const hal::SampleBlock* acquire() override { return queue_.empty() ? nullptr : &queue_.front(); }
  void release() override { queue_.pop_front(); }
  void push(const hal::SampleBlock& b) { queue_.push_back(b); }
  [[nodiscard]] std::uint16_t rate_hz() const { return rate_hz_; }
  [[nodiscard]] int starts() const { return starts_; }

 private:
  fw::FrontEnd fe_;
  std::deque<hal::SampleBlock> queue_;
  std::uint16_t rate_hz_ = 0;
  int starts_ = 0;
};

// A device on a board whose EMG comes from a synthetic generator, 1 ms blocks.
struct Bench {
  explicit Bench(const fw::SynthSpec& spec, std::size_t block_frames = 2)
      : gen(spec), sampler(gen.front_end()), clock(false), block_frames_(block_frames) {}

  hal::Board board() { return hal::Board{sampler, clock, storage, led, watchdog, system, &hid, &can, 42, 1}; }

  // Generates and feeds the next block (sequence += 1), polls the device. False at the end.
  bool step(fw::Device& dev) {
    hal::SampleBlock b{};
    const std::size_t first = gen.position();
    const std::size_t n = gen.generate(b.samples, block_frames_);
    if (n == 0) return false;
    b.frames = static_cast<std::uint16_t>(n);
    b.sequence = sequence++;
    b.first_sample_us =
        static_cast<std::uint64_t>(static_cast<double>(first) * 1e6 / static_cast<double>(gen.spec().sample_rate_hz));
    clock.advance_to(b.first_sample_us + static_cast<std::uint64_t>(static_cast<double>(n) * 1e6 /
                                                                    static_cast<double>(gen.spec().sample_rate_hz)));
    if (!gen.lose_block(first, n)) sampler.push(b);
    dev.poll();
    if (system.take_reset()) {
      ++reboots;
      if (on_reset) on_reset();  // e.g. what a chip reset does to the USB controller
      dev.boot();
    }
    if (after_pass) after_pass();  // e.g. the USB host's IN token of this 1 ms frame
    return true;
  }
  void run_for(fw::Device& dev, float seconds) {
    const auto blocks =
        static_cast<std::size_t>(seconds * gen.spec().sample_rate_hz / static_cast<float>(block_frames_));
    for (std::size_t k = 0; k < blocks && step(dev); ++k) {
    }
  }

  fw::SyntheticEmg gen;
  ManualSampler sampler;
  sim::SimClock clock;
  sim::FlashStorage storage;
  sim::SimLed led;
  sim::SimWatchdog watchdog;
  sim::SimSystem system;
  QueueHid hid;
  QueueCan can;
  std::uint32_t sequence = 0;
  int reboots = 0;
  std::function<void()> on_reset;
  std::function<void()> after_pass;

 private:
  std::size_t block_frames_;
};

}  // namespace tonus::test
