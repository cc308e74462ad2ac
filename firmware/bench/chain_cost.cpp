// Workload for measuring the firmware's per-sample cost in instructions
// (callgrind on the host build, see callgrind_cost.sh). Runs one of:
//   chain  N  - N samples through one channel's chain (chain_step)
//   quality N - the same plus its quality detectors (chain_step + quality_step)
//   frame  N  - N frames of 8 channels through the whole Device (chain,
//               quality, calibration bookkeeping, levels and a 1 kHz report)
// on a pre-generated synthetic EMG, so generation is not counted.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/quality.hpp"
#include "tonus/firmware/synthetic.hpp"

namespace {

using namespace tonus;

volatile float g_sink = 0.0F;

class NullHal final : public hal::EmgSampler,
                      public hal::Clock,
                      public hal::Storage,
                      public hal::StatusLed,
                      public hal::Watchdog,
                      public hal::SystemControl,
                      public hal::UsbHid {
 public:
  explicit NullHal(const std::vector<std::int16_t>& samples) : samples_(samples) {}
  [[nodiscard]] fw::FrontEnd front_end() const override { return fw::FrontEnd{}; }
  bool start(std::uint16_t) override { return true; }
  const hal::SampleBlock* acquire() override { return ready_ ? &block_ : nullptr; }
  void release() override { ready_ = false; }
  bool next(std::size_t frames) {
    if ((pos_ + frames) * fw::kChannels > samples_.size()) return false;
    std::memcpy(block_.samples.data(), samples_.data() + pos_ * fw::kChannels,
                frames * fw::kChannels * sizeof(std::int16_t));
    block_.frames = static_cast<std::uint16_t>(frames);
    block_.sequence = seq_++;
    block_.first_sample_us = pos_ * 500U;
    pos_ += frames;
    now_ = pos_ * 500U;
    ready_ = true;
    return true;
  }
  [[nodiscard]] std::uint64_t now_us() const override { return now_; }
  [[nodiscard]] std::size_t sector_size() const override { return 0; }
  [[nodiscard]] std::size_t sector_count() const override { return 0; }
  bool read(std::size_t, std::span<std::uint8_t>) override { return false; }
  bool erase(std::size_t) override { return false; }
  bool program(std::size_t, std::span<const std::uint8_t>) override { return false; }
  void show(hal::LedPattern) override {}
  void kick() override {}
  [[nodiscard]] bool caused_last_reset() const override { return false; }
  void reset() override {}
  [[nodiscard]] bool connected() const override { return true; }
  void service() override {}
  [[nodiscard]] bool idle() const override { return true; }
  bool send_input(const proto::hid::Report& r) override {
    g_sink = g_sink + static_cast<float>(r[20]);
    return true;
  }
  bool receive_output(proto::hid::Report&, std::size_t&) override { return false; }

 private:
  const std::vector<std::int16_t>& samples_;
  hal::SampleBlock block_{};
  bool ready_ = false;
  std::size_t pos_ = 0;
  std::uint32_t seq_ = 0;
  std::uint64_t now_ = 0;
};

// Only this function is counted (callgrind --toggle-collect=*measured_loops*):
// designs happen inside it once, the loops dominate; the script differences
// two lengths to cancel that fixed part exactly.
__attribute__((noinline)) bool measured_loops(const char* what, const std::vector<std::int16_t>& samples, long n) {
  const proto::DeviceConfig cfg = fw::default_config(fw::FrontEnd{});
  if (std::strcmp(what, "chain") == 0 || std::strcmp(what, "quality") == 0) {
    const bool quality = what[0] == 'q';
    const fw::ChainModel m = fw::design_chain(cfg);
    const fw::QualityModel qm = fw::design_quality(fw::FrontEnd{}, m.sample_rate_hz, true);
    fw::ChannelState s;
    fw::QualityState q;
    float acc = 0.0F;
    for (long k = 0; k < n; ++k) {
      fw::ChainTaps taps;
      const std::int16_t x = samples[static_cast<std::size_t>(k) * fw::kChannels];
      acc += fw::chain_step(m, s, x, taps);
      if (quality) fw::quality_step(qm, q, x, taps);
    }
    g_sink = acc;
    return true;
  }
  if (std::strcmp(what, "frame") == 0) {
    static NullHal hal_(samples);
    static hal::Board board{hal_, hal_, hal_, hal_, hal_, hal_, &hal_, nullptr, 0, 0};
    static fw::Device dev(board);
    dev.boot();
    for (long k = 0; k + 2 <= n && hal_.next(2); k += 2) dev.poll();
    g_sink = static_cast<float>(dev.reports());
    return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s chain|quality|frame N\n", argv[0]);
    return 2;
  }
  const char* what = argv[1];
  const long n = std::strtol(argv[2], nullptr, 10);
  if (n <= 0 || n > 10000000) return 2;
  fw::SynthSpec spec;
  spec.scenario = fw::Scenario::ramp;
  spec.seconds = static_cast<float>(n) / 2000.0F + 0.01F;
  fw::SyntheticEmg gen(spec);
  std::vector<std::int16_t> samples(static_cast<std::size_t>(n + 2) * fw::kChannels);
  gen.generate(samples, static_cast<std::size_t>(n + 2));

  if (!measured_loops(what, samples, n)) return 2;
  std::printf("%s %ld done (%g)\n", what, n, static_cast<double>(g_sink));
  return 0;
}
