// Faster stiffness (issue 10): the step from rest to a co-contraction reaches
// 90 % of the level within 60 ms, and the levels chatter no more than with the
// configured envelope alone (the path before), on synthetic and real EMG.
//
// "Before" is computed beside "after" on the same input: the levels from the
// displayed envelope (what the device computed them from until now) against
// the levels from the level envelope. Chatter = level transitions per second
// and the level's standard deviation (% of full scale) over a steady segment.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "emg_recording.hpp"
#include "fake_board.hpp"
#include "summary.hpp"
#include "tonus/firmware/calibration.hpp"
#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/levels.hpp"
#include "tonus/firmware/synthetic.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

using PairLevels = std::array<std::uint16_t, kPairs>;

// Pair levels at the report rate from the displayed envelope ([0], before) and
// from the level envelope ([1], after), on frames given by `frame(k, out)`.
struct TwoPaths {
  std::array<std::vector<PairLevels>, 2> levels;
  std::uint32_t changes = 0;  // confirmed changes of the level envelope, all channels
};

template <class Frame>
TwoPaths run_both(const proto::DeviceConfig& cfg, const Calibration& cal, std::size_t frames, Frame frame,
                  const std::array<std::size_t, kChannels>& channel_of) {
  const ChainModel chain = design_chain(cfg);
  const LevelModel lm = design_levels(cfg);
  std::array<ChannelState, kChannels> st{};
  std::array<LevelState, 2> ls{};
  TwoPaths out;
  std::uint32_t phase = 0;
  std::array<std::array<float, kChannels>, 2> env{};
  std::array<float, kChannels> x{};
  for (std::size_t k = 0; k < frames; ++k) {
    frame(k, x);
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      ChainTaps taps;
      env[0][ch] = chain_step(chain, st[ch], x[ch], taps);
      env[1][ch] = level_envelope(chain, st[ch]);
    }
    phase += cfg.report_rate_hz;  // as the device: levels once per report
    if (phase < cfg.sample_rate_hz) continue;
    phase -= cfg.sample_rate_hz;
    for (std::size_t path = 0; path < 2; ++path) {
      std::array<float, kPairs> c{};
      for (std::size_t p = 0; p < kPairs; ++p) {
        c[p] = cocontraction(cfg.measure, normalise(cal, 2 * p, env[path][channel_of[2 * p]]),
                             normalise(cal, 2 * p + 1, env[path][channel_of[2 * p + 1]])) /
               cal.cocontraction[p];
      }
      std::array<std::uint16_t, kGroups> groups{};
      levels_step(lm, ls[path], c, groups);
      out.levels[path].push_back(ls[path].pair_level);
    }
  }
  for (const ChannelState& s : st) out.changes += s.level.changes;
  return out;
}

struct Chatter {
  double per_s = 0.0;  // level transitions per second
  double sd = 0.0;     // % of full scale
  double mean = 0.0;   // % of full scale
  double seconds = 0.0;
  void add(const Chatter& o) {  // time-weighted
    per_s += o.per_s * o.seconds;
    sd += o.sd * o.seconds;
    mean += o.mean * o.seconds;
    seconds += o.seconds;
  }
  [[nodiscard]] Chatter averaged() const {
    return seconds > 0.0 ? Chatter{per_s / seconds, sd / seconds, mean / seconds, seconds} : *this;
  }
};

Chatter chatter(const std::vector<PairLevels>& lv, std::size_t a, std::size_t b, std::size_t p, double rate) {
  Chatter c;
  double s = 0.0, s2 = 0.0;
  int transitions = 0;
  for (std::size_t k = a; k < b; ++k) {
    const double v = lv[k][p] / 655.35;
    s += v;
    s2 += v * v;
    if (k > a && lv[k][p] != lv[k - 1][p]) ++transitions;
  }
  const auto n = static_cast<double>(b - a);
  c.mean = s / n;
  c.sd = std::sqrt(std::max(0.0, s2 / n - c.mean * c.mean));
  c.seconds = n / rate;
  c.per_s = transitions / c.seconds;
  return c;
}

constexpr std::array<std::size_t, kChannels> kSame = {0, 1, 2, 3, 4, 5, 6, 7};

void check_not_worse(const std::string& name, const Chatter& before, const Chatter& after) {
  MESSAGE(name << ": mean level " << before.mean << " %; transitions/s " << before.per_s << " -> " << after.per_s
               << ", level sd " << before.sd << " -> " << after.sd << " % FS");
  INFO(name);
  // Not worse. After a real change the two paths' states differ for a few tau
  // (the level envelope hands its running mean to the one-pole), which can move
  // single hysteresis transitions later on: 0.5 % covers that, far below the
  // counting noise of the transitions (1500 in a minute: 2.6 %).
  CHECK(after.per_s <= before.per_s * 1.005 + 1e-9);
  CHECK(after.sd <= before.sd * 1.005 + 1e-9);
}

}  // namespace

TEST_CASE("step_latency measures a first-order step at its closed-form times") {
  // level = L (1 - exp(-t / tau)) from t0, at 500 Hz: 10 / 50 / 90 % at tau ln(10/9), tau ln 2, tau ln 10.
  const double tau_ms = 20.0, full = 40000.0;
  std::vector<std::uint64_t> t;
  std::vector<std::array<std::uint16_t, kGroups>> lv;
  const std::uint64_t t0 = 1000000;
  for (std::uint64_t us = 2000; us < 2000000; us += 2000) {
    const double x = us < t0 ? 0.0 : full * (1.0 - std::exp(-static_cast<double>(us - t0) / 1000.0 / tau_ms));
    const auto l = static_cast<std::uint16_t>(std::lround(x));
    t.push_back(us);
    lv.push_back({l, l, 0, l});  // group 2 does not step: left out
  }
  const sim::StepLatency r = sim::step_latency(t, lv, t0);
  CHECK(r.groups == 3);
  // First report at or after the crossing: within one report period (2 ms) after it.
  CHECK(r.ms10 >= tau_ms * std::log(10.0 / 9.0));
  CHECK(r.ms10 < tau_ms * std::log(10.0 / 9.0) + 2.0);
  CHECK(r.ms50 >= tau_ms * std::log(2.0));
  CHECK(r.ms50 < tau_ms * std::log(2.0) + 2.0);
  CHECK(r.ms90 >= tau_ms * std::log(10.0));
  CHECK(r.ms90 < tau_ms * std::log(10.0) + 2.0);
}

TEST_CASE("step from rest to co-contraction: 90 % of the level within 60 ms, through the whole device") {
  // A single 2 s run crosses 90 % at a noisy time (the level has ~10 % noise for
  // 100 ms after the step: that is all the EMG there is yet). The step response
  // is the mean over seeds; each run is reported, and their median checked.
  double worst90 = 0.0, before90 = 0.0;
  std::vector<double> each90;
  std::vector<std::array<double, kGroups>> ensemble, ensemble_before;  // mean level per report over the seeds
  std::vector<std::uint64_t> times;
  constexpr int kSeeds = 10;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    SynthSpec spec;
    spec.scenario = Scenario::step;
    spec.seed = static_cast<std::uint64_t>(seed);
    spec.seconds = 2.0F;
    test::Bench b(spec);
    hal::Board board = b.board();
    Device dev(board);
    dev.boot();
    struct Seen {
      sim::Summary after, before;
      LevelModel lm;
      LevelState ls;
      proto::CoContractionMeasure measure{};
    } seen;
    seen.after.keep_levels = true;
    seen.before.keep_levels = true;
    seen.lm = design_levels(dev.config());
    seen.measure = dev.config().measure;
    dev.set_report_observer(
        [](void* ctx, const proto::StreamMessage& m) {
          auto& s = *static_cast<Seen*>(ctx);
          s.after.add(m, m.device_time_us);
          // Before: the levels from the displayed envelopes the stream carries (uncalibrated: c = min(f, e)).
          proto::StreamMessage old = m;
          std::array<float, kPairs> c{};
          for (std::size_t p = 0; p < kPairs; ++p) {
            const auto q15 = [](std::uint16_t v) { return static_cast<float>(v) / 32768.0F; };
            c[p] = cocontraction(s.measure, q15(m.envelopes[2 * p]), q15(m.envelopes[2 * p + 1]));
          }
          std::array<std::uint16_t, kGroups> g{};
          levels_step(s.lm, s.ls, c, g);
          for (std::size_t k = 0; k < kGroups; ++k) old.levels[k] = g[k];
          s.before.add(old, m.device_time_us);
        },
        &seen);
    while (b.step(dev)) {
    }
    REQUIRE(!seen.after.level_time_us.empty());
    const std::uint64_t step_us = sim::frame_time_us(seen.after.level_time_us.front(), step_frame(spec),
                                                     dev.config().sample_rate_hz, dev.config().report_rate_hz);
    // The step lands exactly on the synthetic frame: 1 s at 2 kHz.
    CHECK(step_us == 1000000);
    const sim::StepLatency now = sim::step_latency(seen.after.level_time_us, seen.after.levels, step_us);
    const sim::StepLatency old = sim::step_latency(seen.before.level_time_us, seen.before.levels, step_us);
    INFO("seed " << seed);
    CHECK(now.groups == kGroups);
    CHECK(now.ms10 >= 0.0);
    CHECK(now.ms10 <= now.ms50);
    CHECK(now.ms50 <= now.ms90);
    CHECK(now.ms90 >= 0.0);
    CHECK(now.ms90 <= 100.0);
    CHECK(old.ms90 > 120.0);  // the path before: the 100 ms envelope
    worst90 = std::max(worst90, now.ms90);
    each90.push_back(now.ms90);
    before90 += old.ms90;
    if (ensemble.empty()) {
      ensemble.resize(seen.after.levels.size());
      ensemble_before.resize(seen.after.levels.size());
      times = seen.after.level_time_us;
    }
    REQUIRE(seen.after.levels.size() == ensemble.size());
    for (std::size_t k = 0; k < ensemble.size(); ++k) {
      for (std::size_t g = 0; g < kGroups; ++g) {
        ensemble[k][g] += seen.after.levels[k][g] / double{kSeeds};
        ensemble_before[k][g] += seen.before.levels[k][g] / double{kSeeds};
      }
    }
  }
  const auto response = [&](const std::vector<std::array<double, kGroups>>& levels) {
    std::vector<std::array<std::uint16_t, kGroups>> rounded;
    for (const auto& e : levels) {
      rounded.push_back({});
      for (std::size_t g = 0; g < kGroups; ++g) rounded.back()[g] = static_cast<std::uint16_t>(std::lround(e[g]));
    }
    return sim::step_latency(times, rounded, 1000000);
  };
  const sim::StepLatency mean = response(ensemble), mean_before = response(ensemble_before);
  std::sort(each90.begin(), each90.end());
  MESSAGE("step to level over " << kSeeds << " seeds (device time): mean step response 10/50/90 % " << mean.ms10
                                << " / " << mean.ms50 << " / " << mean.ms90 << " ms; single runs' 90 %: median "
                                << each90[kSeeds / 2] << " ms, worst " << worst90
                                << " ms; before: mean step response 10/50/90 % " << mean_before.ms10 << " / "
                                << mean_before.ms50 << " / " << mean_before.ms90 << " ms, single runs' 90 % mean "
                                << before90 / kSeeds << " ms");
  CHECK(mean.ms90 >= 0.0);
  CHECK(mean.ms90 <= 60.0);
  CHECK(each90[kSeeds / 2] <= 60.0);
}

TEST_CASE("chatter on steady synthetic co-contraction and at rest: no worse than the configured envelope") {
  for (const float effort : {0.1F, 0.2F, 0.35F, 0.5F, 0.7F}) {
    Chatter rest[2], steady[2];
    std::uint32_t changes = 0;
    for (std::uint64_t seed = 101; seed <= 103; ++seed) {
      SynthSpec spec;
      spec.scenario = Scenario::step;  // rest for 10 s, then `effort` for 10 s
      spec.seed = seed;
      spec.seconds = 20.0F;
      spec.step_activation = effort;
      SyntheticEmg gen(spec);
      const proto::DeviceConfig cfg = default_config(gen.front_end());
      const Calibration cal = default_calibration(gen.front_end());
      std::array<std::int16_t, kChannels> buf{};
      const TwoPaths r = run_both(
          cfg, cal, gen.total_frames(),
          [&](std::size_t, std::array<float, kChannels>& x) {
            gen.generate(buf, 1);
            for (std::size_t ch = 0; ch < kChannels; ++ch) x[ch] = buf[ch];
          },
          kSame);
      changes += r.changes;
      const double rate = cfg.report_rate_hz;
      const auto at = [&](double s) { return static_cast<std::size_t>(s * rate); };
      for (std::size_t path = 0; path < 2; ++path) {
        for (std::size_t p = 0; p < kPairs; ++p) {
          rest[path].add(chatter(r.levels[path], at(1.0), at(10.0), p, rate));
          steady[path].add(chatter(r.levels[path], at(11.0), at(20.0), p, rate));
        }
      }
    }
    // One confirmed change per channel at power-up and one at the step: none in the steady parts.
    CHECK(changes == std::uint32_t{3 * 2} * kChannels);
    const std::string name = "synthetic effort " + std::to_string(effort).substr(0, 4);
    check_not_worse(name + " steady", steady[0].averaged(), steady[1].averaged());
    check_not_worse(name + " rest", rest[0].averaged(), rest[1].averaged());
  }
}

TEST_CASE("chatter on the real recordings: no worse than the configured envelope") {
  const std::string dir = std::string(TONUS_SHARED_DATA_DIR) + "/emg/";
  const auto load = [&](const std::string& name) {
    sim::Recording rec;
    std::string error;
    REQUIRE_MESSAGE(sim::load_recording(dir + name, rec, error), error);
    return rec;
  };

  SUBCASE("Myo 200 Hz: fist (co-contraction), wrist flexion, rest") {
    const sim::Recording fist = load("myo_12345-1_fist.txt"), flex = load("myo_12345-1_flexion.txt");
    // Pairs and calibration as in test_recordings.cpp: electrodes k and k+4 face each
    // other; baseline = mean rest envelope, reference = peak envelope (displayed one).
    constexpr std::array<std::size_t, kChannels> myo_of_band = {0, 4, 1, 5, 2, 6, 3, 7};
    const proto::DeviceConfig cfg = default_config(fist.front_end);
    Calibration cal = default_calibration(fist.front_end);
    {
      const ChainModel m = design_chain(cfg);
      std::array<double, kChannels> rest{};
      std::array<float, kChannels> peak{};
      std::size_t n = 0;
      for (const sim::Recording* rec : {&fist, &flex}) {
        std::array<ChannelState, kChannels> st{};
        for (std::size_t k = 0; k < rec->frames.size(); ++k) {
          for (std::size_t ch = 0; ch < kChannels; ++ch) {
            ChainTaps taps;
            const float e = chain_step(m, st[ch], rec->frames[k][ch], taps);
            if (k < 200) continue;
            if (rec->labels[k] == 0) rest[ch] += static_cast<double>(e);
            peak[ch] = std::max(peak[ch], e);
          }
          if (k >= 200 && rec->labels[k] == 0) ++n;
        }
      }
      for (std::size_t b = 0; b < kChannels; ++b) {
        cal.baseline[b] = static_cast<float>(rest[myo_of_band[b]] / static_cast<double>(n));
        cal.reference[b] = peak[myo_of_band[b]];
      }
    }
    for (const sim::Recording* rec : {&fist, &flex}) {
      const TwoPaths r = run_both(
          cfg, cal, rec->frames.size(),
          [&](std::size_t k, std::array<float, kChannels>& x) {
            for (std::size_t ch = 0; ch < kChannels; ++ch) x[ch] = rec->frames[k][ch];
          },
          myo_of_band);
      REQUIRE(r.levels[0].size() == rec->frames.size());  // 200 Hz: a report per frame
      const double rate = cfg.report_rate_hz;
      // The labels are prompts: onsets follow them by up to 0.8 s (the level
      // envelope's confirmed changes fall 0.1-0.8 s after a label change), so a
      // segment is steady from 1.5 s after its label on.
      const auto settle = static_cast<std::size_t>(1.5 * rate);
      for (const int label : {0, rec == &fist ? 7 : 1}) {
        Chatter c[2];
        for (std::size_t k = 0; k < rec->frames.size();) {
          std::size_t e = k;
          while (e < rec->frames.size() && rec->labels[e] == rec->labels[k]) ++e;
          if (rec->labels[k] == label && e - k > 2 * settle) {
            for (std::size_t path = 0; path < 2; ++path) {
              for (std::size_t p = 0; p < kPairs; ++p) c[path].add(chatter(r.levels[path], k + settle, e, p, rate));
            }
          }
          k = e;
        }
        const std::string what = label == 0 ? "rest" : (label == 7 ? "fist" : "wrist flexion");
        check_not_worse("Myo " + std::string(rec == &fist ? "fist file " : "flexion file ") + what, c[0].averaged(),
                        c[1].averaged());
      }
    }
  }

  SUBCASE("BioSPPy 1 kHz: bursts of several strengths and rest (one channel as both sides of a pair)") {
    const sim::Recording rec = load("biosppy_emg_1.txt");
    const proto::DeviceConfig cfg = default_config(rec.front_end);
    // Baseline: the mean displayed envelope over the rest after 42 s; reference: its peak.
    Calibration cal = default_calibration(rec.front_end);
    {
      const ChainModel m = design_chain(cfg);
      ChannelState st;
      double rest = 0.0;
      std::size_t n = 0;
      float peak = 0.0F;
      for (std::size_t k = 0; k < rec.frames.size(); ++k) {
        ChainTaps taps;
        const float e = chain_step(m, st, rec.frames[k][0], taps);
        if (k < 1000) continue;
        peak = std::max(peak, e);
        if (k >= 43000) {
          rest += static_cast<double>(e);
          ++n;
        }
      }
      for (std::size_t ch = 0; ch < kChannels; ++ch) {
        cal.baseline[ch] = static_cast<float>(rest / static_cast<double>(n));
        cal.reference[ch] = peak;
      }
    }
    constexpr std::array<std::size_t, kChannels> first = {0, 0, 0, 0, 0, 0, 0, 0};
    const TwoPaths r = run_both(
        cfg, cal, rec.frames.size(), [&](std::size_t k, std::array<float, kChannels>& x) { x.fill(rec.frames[k][0]); },
        first);
    const double rate = cfg.report_rate_hz;
    const auto at = [&](double t) { return static_cast<std::size_t>(t * rate); };
    // Rest: after the last burst (SOURCES.md: rest only after ~42 s) and after a
    // brief activation at 44.97 s (the fast envelope triples for ~80 ms, which the
    // level envelope follows: a response, not chatter).
    check_not_worse("BioSPPy rest 45.5-63 s", chatter(r.levels[0], at(45.5), at(63.0), 0, rate),
                    chatter(r.levels[1], at(45.5), at(63.0), 0, rate));
    // The bursts (SOURCES.md: 1-s standard deviation ~54 at 1-2 s, 90-117 at 15-17 s,
    // 33-43 at 25-27 s, 13-16 at 36-41 s) are not steady: reported, not judged.
    const std::array<std::pair<double, double>, 5> bursts{
        {{1.0, 2.0}, {15.0, 17.0}, {25.0, 27.0}, {36.0, 41.0}, {42.0, 63.0}}};
    for (const auto& [from, to] : bursts) {
      const Chatter before = chatter(r.levels[0], at(from), at(to), 0, rate);
      const Chatter after = chatter(r.levels[1], at(from), at(to), 0, rate);
      MESSAGE("BioSPPy " << from << "-" << to << " s (not steady): mean level " << before.mean << " %; transitions/s "
                         << before.per_s << " -> " << after.per_s << ", level sd " << before.sd << " -> " << after.sd);
    }
  }
}
