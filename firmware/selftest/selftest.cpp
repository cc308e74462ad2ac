#include "selftest.hpp"

#include <cmath>

#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/synthetic.hpp"
#include "tonus/protocol/crc16.hpp"

namespace tonus::fw {

namespace {

constexpr std::size_t kBlockFrames = 2;  // 1 ms at 2 kHz, as the band's DMA half-buffer

class VirtualClock final : public hal::Clock {
 public:
  [[nodiscard]] std::uint64_t now_us() const override { return now_; }
  std::uint64_t now_ = 0;
};

class SyntheticSampler final : public hal::EmgSampler {
 public:
  explicit SyntheticSampler(SyntheticEmg& gen, VirtualClock& clock) : gen_(gen), clock_(clock) {}
  [[nodiscard]] FrontEnd front_end() const override { return gen_.front_end(); }
  bool start(std::uint16_t rate_hz) override { return rate_hz == kSelftestSampleRateHz; }
  const hal::SampleBlock* acquire() override { return ready_ ? &block_ : nullptr; }
  void release() override { ready_ = false; }
  void restart() {
    ready_ = false;
    sequence_ = 0;
  }
  bool produce() {
    const std::size_t first = gen_.position();
    const std::size_t n = gen_.generate(block_.samples, kBlockFrames);
    if (n == 0) return false;
    block_.sequence = sequence_++;
    block_.frames = static_cast<std::uint16_t>(n);
    block_.first_sample_us = first * 1000000U / kSelftestSampleRateHz;
    clock_.now_ = (first + n) * 1000000U / kSelftestSampleRateHz;
    ready_ = true;
    return true;
  }

 private:
  SyntheticEmg& gen_;
  VirtualClock& clock_;
  hal::SampleBlock block_{};
  bool ready_ = false;
  std::uint32_t sequence_ = 0;
};

class RamStorage final : public hal::Storage {
 public:
  [[nodiscard]] std::size_t sector_size() const override { return kSector; }
  [[nodiscard]] std::size_t sector_count() const override { return 2; }
  bool read(std::size_t offset, std::span<std::uint8_t> out) override {
    if (offset + out.size() > bytes_.size()) return false;
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = bytes_[offset + k];
    return true;
  }
  bool erase(std::size_t sector) override {
    if (sector >= 2) return false;
    for (std::size_t k = 0; k < kSector; ++k) bytes_[sector * kSector + k] = 0xFF;
    return true;
  }
  bool program(std::size_t offset, std::span<const std::uint8_t> data) override {
    if (offset + data.size() > bytes_.size()) return false;
    for (std::size_t k = 0; k < data.size(); ++k) bytes_[offset + k] &= data[k];
    return true;
  }
  RamStorage() { bytes_.fill(0xFF); }

 private:
  static constexpr std::size_t kSector = 2 * kRecordSlot;
  std::array<std::uint8_t, 2 * kSector> bytes_{};
};

class Nothing final : public hal::StatusLed, public hal::Watchdog, public hal::SystemControl {
 public:
  void show(hal::LedPattern) override {}
  void kick() override {}
  [[nodiscard]] bool caused_last_reset() const override { return false; }
  void reset() override {}
};

struct Collector {
  SelftestResult* result;
  SelftestSink sink;
  void* context;
  std::uint32_t total_reports;
  // Reports are queued during Device::poll and digested after it, so that the
  // self-test's own bookkeeping (CRC, UART) stays out of the measured cost.
  std::array<proto::StreamMessage, 4> pending{};
  std::size_t pending_count = 0;
};

void queue(void* ctx, const proto::StreamMessage& m) {
  auto& c = *static_cast<Collector*>(ctx);
  if (c.pending_count < c.pending.size()) c.pending[c.pending_count++] = m;
}

void digest(Collector& c, const proto::StreamMessage& m) {
  SelftestResult& r = *c.result;
  for (std::size_t g = 0; g < kGroups; ++g) {
    if (m.levels[g] > r.level_max[g]) r.level_max[g] = m.levels[g];
  }
  // Mid-point of the co-contraction step (30..65 % of the run) and the end.
  if (r.reports == c.total_reports / 2) {
    for (std::size_t g = 0; g < kGroups; ++g) r.level_at_mid[g] = m.levels[g];
  }
  for (std::size_t g = 0; g < kGroups; ++g) r.level_final[g] = m.levels[g];
  for (std::size_t ch = 0; ch < kChannels; ++ch) r.envelope_final[ch] = m.envelopes[ch];
  r.flags_seen = static_cast<std::uint16_t>(r.flags_seen | m.electrode_off | m.saturation | m.artifact);
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  if (proto::encode_stream(m, bytes, n) == proto::Error::ok) {
    r.stream_crc = proto::crc16_ccitt(std::span<const std::uint8_t>(bytes).first(n), r.stream_crc);
  }
  ++r.reports;
  if (c.sink != nullptr) c.sink(c.context, m);
}

// Appends text / an unsigned / a signed integer; keeps the buffer NUL-terminated.
struct Writer {
  char* out;
  std::size_t cap;
  std::size_t len = 0;
  void text(const char* s) {
    while (*s != '\0' && len + 1 < cap) out[len++] = *s++;
    out[len] = '\0';
  }
  void number(std::int64_t v) {
    char digits[24];
    std::size_t n = 0;
    const bool neg = v < 0;
    std::uint64_t u = neg ? static_cast<std::uint64_t>(-v) : static_cast<std::uint64_t>(v);
    do {
      digits[n++] = static_cast<char>('0' + u % 10U);
      u /= 10U;
    } while (u != 0);
    if (neg) digits[n++] = '-';
    char s[24];
    for (std::size_t k = 0; k < n; ++k) s[k] = digits[n - 1 - k];
    s[n] = '\0';
    text(s);
  }
  void field(const char* key, std::int64_t v) {
    text(key);
    text("=");
    number(v);
    text("\n");
  }
  template <std::size_t N>
  void list(const char* key, const std::array<std::uint16_t, N>& v) {
    text(key);
    text("=");
    for (std::size_t k = 0; k < N; ++k) {
      if (k != 0) text(",");
      number(v[k]);
    }
    text("\n");
  }
};

}  // namespace

void run_selftest(SelftestResult& out, SelftestSink sink, void* context, TickCounter ticks) {
  out = SelftestResult{};
  SynthSpec spec;
  spec.scenario = Scenario::selftest;
  spec.seed = kSelftestSeed;
  spec.sample_rate_hz = static_cast<float>(kSelftestSampleRateHz);
  spec.seconds = kSelftestSeconds;
  static SyntheticEmg gen(spec);  // static: large objects stay off the small stack of the band
  gen = SyntheticEmg(spec);
  static VirtualClock clock;
  clock.now_ = 0;
  static SyntheticSampler sampler(gen, clock);
  sampler.restart();
  static RamStorage storage;
  storage = RamStorage();
  static Nothing nothing;
  static hal::Board board{sampler, clock, storage, nothing, nothing, nothing, nullptr, nullptr, 0, 0};
  static Device device(board);

  static Collector c{};
  c = Collector{&out, sink, context, 0};
  device.set_report_observer(&queue, &c);
  device.boot();
  // Reports in the run at the configured rate (the mid-point report is sampled).
  c.total_reports =
      static_cast<std::uint32_t>(gen.total_frames() * device.config().report_rate_hz / device.config().sample_rate_hz);
  while (sampler.produce()) {
    if (ticks == nullptr) {
      device.poll();
    } else {
      const std::uint32_t t0 = ticks();
      device.poll();
      out.poll_ticks += ticks() - t0;
      out.frames += kBlockFrames;
    }
    for (std::size_t k = 0; k < c.pending_count; ++k) digest(c, c.pending[k]);
    c.pending_count = 0;
  }
  device.set_report_observer(nullptr, nullptr);
  out.lost_blocks = device.stats().lost_blocks;

  const ChainModel& m = device.chain();
  const double fs = static_cast<double>(m.sample_rate_hz);
  out.notch_depth_mdb = static_cast<std::int32_t>(std::lround(20000.0 * std::log10(magnitude(m.notch[0], 50.0, fs))));
  const double hp = magnitude(m.highpass[0], 20.0, fs) * magnitude(m.highpass[1], 20.0, fs);
  out.highpass_corner_mdb = static_cast<std::int32_t>(std::lround(20000.0 * std::log10(hp)));
  out.group_delay_us = static_cast<std::uint32_t>(std::lround(chain_group_delay(m).total_s() * 1e6));
}

std::size_t format_selftest(const SelftestResult& r, char* out, std::size_t capacity) {
  Writer w{out, capacity};
  w.text("tonus-selftest begin\n");
  w.field("reports", r.reports);
  w.field("lost_blocks", r.lost_blocks);
  w.list("level_max", r.level_max);
  w.list("level_mid", r.level_at_mid);
  w.list("level_final", r.level_final);
  w.list("envelope_final", r.envelope_final);
  w.field("flags_seen", r.flags_seen);
  w.field("notch_depth_mdb", r.notch_depth_mdb);
  w.field("highpass_corner_mdb", r.highpass_corner_mdb);
  w.field("group_delay_us", r.group_delay_us);
  w.field("stream_crc", r.stream_crc);
  w.text("tonus-selftest end\n");
  return w.len;
}

}  // namespace tonus::fw
