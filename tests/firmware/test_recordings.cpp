// The real recordings of shared/data/emg (see its SOURCES.md) through the
// firmware's own chain, configured for each recording's rate.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <tuple>
#include <vector>

#include "emg_recording.hpp"
#include "tonus/firmware/calibration.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/levels.hpp"
#include "tonus/firmware/quality.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

const std::string kDir = std::string(TONUS_SHARED_DATA_DIR) + "/emg/";

sim::Recording load(const std::string& name) {
  sim::Recording rec;
  std::string error;
  REQUIRE_MESSAGE(sim::load_recording(kDir + name, rec, error), error);
  return rec;
}

struct Run {
  std::vector<std::array<float, kChannels>> envelope;  // per frame
  std::vector<std::array<QualityFlags, kChannels>> flags;
  ChainModel chain;
};

Run run_chain(const sim::Recording& rec) {
  const proto::DeviceConfig cfg = default_config(rec.front_end);
  REQUIRE(check_device_config(cfg, rec.front_end) == proto::ConfigField::none);
  Run r;
  r.chain = design_chain(cfg);
  const QualityModel qm = design_quality(rec.front_end, r.chain.sample_rate_hz, r.chain.notch_count > 0);
  std::array<ChannelState, kChannels> st{};
  std::array<QualityState, kChannels> qs{};
  for (const sim::Frame& f : rec.frames) {
    std::array<float, kChannels> env{};
    std::array<QualityFlags, kChannels> fl{};
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      ChainTaps taps;
      env[ch] = chain_step(r.chain, st[ch], f[ch], taps);
      quality_step(qm, qs[ch], f[ch], taps);
      fl[ch] = qs[ch].held;
    }
    r.envelope.push_back(env);
    r.flags.push_back(fl);
  }
  return r;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

TEST_CASE("BioSPPy 1 kHz: rest and activity separate clearly in the envelope, rest raises no flags") {
  const sim::Recording rec = load("biosppy_emg_1.txt");
  CHECK(rec.sample_rate_hz == doctest::Approx(1000.0F));
  CHECK(rec.frames.size() == 63880);
  const Run r = run_chain(rec);
  CHECK(r.chain.lowpass_sections == 2);  // 450 Hz is below the 500 Hz Nyquist
  CHECK(r.chain.notch_count == 4);

  // Label 1 s windows independently of the chain, from the raw signal's
  // standard deviation (SOURCES.md: rest ~10 counts, bursts 30..117).
  const std::size_t w = 1000;
  std::vector<double> rest_env, active_env;
  int rest_flagged = 0, rest_windows = 0;
  for (std::size_t start = w; start + w <= rec.frames.size(); start += w) {
    double mean = 0.0, sq = 0.0;
    for (std::size_t k = start; k < start + w; ++k) mean += rec.frames[k][0];
    mean /= static_cast<double>(w);
    for (std::size_t k = start; k < start + w; ++k) sq += (rec.frames[k][0] - mean) * (rec.frames[k][0] - mean);
    const double sd = std::sqrt(sq / static_cast<double>(w));
    // The envelope lags by ~0.1 s: judge it over the second half of the window.
    double env = 0.0;
    bool flagged = false;
    for (std::size_t k = start + w / 2; k < start + w; ++k) env += static_cast<double>(r.envelope[k][0]);
    for (std::size_t k = start; k < start + w; ++k) {
      const QualityFlags& f = r.flags[k][0];
      flagged = flagged || f.electrode_off || f.saturation || f.artifact;
    }
    const std::size_t tail = w - w / 2;  // frames summed above
    env /= static_cast<double>(tail);
    if (sd < 15.0) {
      rest_env.push_back(env);
      ++rest_windows;
      rest_flagged += flagged ? 1 : 0;
    } else if (sd > 30.0) {
      active_env.push_back(env);
    }
  }
  REQUIRE(rest_env.size() > 20);
  REQUIRE(active_env.size() >= 4);
  const double rest_hi = percentile(rest_env, 0.95), active_lo = percentile(active_env, 0.05);
  MESSAGE("BioSPPy envelope: rest p95 " << rest_hi << ", active p5 " << active_lo << " counts; rest windows "
                                        << rest_windows << " flagged " << rest_flagged);
  CHECK(active_lo > 2.0 * rest_hi);  // no overlap, with a factor 2 margin
  CHECK(rest_flagged == 0);
}

TEST_CASE(
    "Myo 200 Hz: a fist raises the co-contraction level, a wrist flexion much less; clean segments raise no flags") {
  const sim::Recording fist = load("myo_12345-1_fist.txt");
  const sim::Recording flex = load("myo_12345-1_flexion.txt");
  const Run rf = run_chain(fist), rx = run_chain(flex);
  CHECK(rf.chain.lowpass_sections == 0);  // 450 Hz is above the 100 Hz Nyquist: dropped
  CHECK(rf.chain.notch_count == 1);

  // Antagonist pairs: the Myo's 8 electrodes ring the forearm, so electrodes
  // k and k+4 face each other across it (flexor side / extensor side).
  constexpr std::array<std::size_t, kChannels> myo_of_band = {0, 4, 1, 5, 2, 6, 3, 7};
  // Normalisation as a calibration would set it: baseline = mean envelope at
  // rest (label 0), reference = each channel's own maximum over both files.
  const std::array<std::pair<const sim::Recording*, const Run*>, 2> both{{{&fist, &rf}, {&flex, &rx}}};
  Calibration cal = default_calibration(fist.front_end);
  const std::size_t settle = 200;  // 1 s of filter start-up
  for (std::size_t b = 0; b < kChannels; ++b) {
    const std::size_t m = myo_of_band[b];
    double rest = 0.0;
    std::size_t n = 0;
    float peak = 0.0F;
    for (const auto& pr : both) {
      for (std::size_t k = settle; k < pr.first->frames.size(); ++k) {
        if (pr.first->labels[k] == 0) {
          rest += static_cast<double>(pr.second->envelope[k][m]);
          ++n;
        }
        peak = std::max(peak, pr.second->envelope[k][m]);
      }
    }
    cal.baseline[b] = static_cast<float>(rest / static_cast<double>(n));
    cal.reference[b] = peak;
  }
  proto::DeviceConfig cfg = default_config(fist.front_end);
  const LevelModel lm = design_levels(cfg);

  // Mean pair level (0..1) over the frames of one label, after the envelope's delay.
  const auto mean_level = [&](const sim::Recording& rec, const Run& r, int label) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t k = settle; k < rec.frames.size(); ++k) {
      if (rec.labels[k] != label || rec.labels[k - 40] != label) continue;  // skip 200 ms after a change
      for (std::size_t p = 0; p < kPairs; ++p) {
        const float f = normalise(cal, 2 * p, r.envelope[k][myo_of_band[2 * p]]);
        const float e = normalise(cal, 2 * p + 1, r.envelope[k][myo_of_band[2 * p + 1]]);
        sum += level_target(lm, cocontraction(cfg.measure, f, e)) / 65535.0;
        ++n;
      }
    }
    return sum / static_cast<double>(n);
  };
  const double fist_level = mean_level(fist, rf, 7), fist_rest = mean_level(fist, rf, 0);
  const double flex_level = mean_level(flex, rx, 1), flex_rest = mean_level(flex, rx, 0);
  MESSAGE("Myo mean co-contraction level: fist " << fist_level << " (rest " << fist_rest << "), wrist flexion "
                                                 << flex_level << " (rest " << flex_rest << ")");
  CHECK(fist_level > 3.0 * fist_rest);
  CHECK(fist_level > 2.0 * flex_level);
  CHECK(flex_level > flex_rest);

  // Flags: none at rest or in flexion; in the fist only saturation, and only
  // where the int8 samples really hit the rails.
  for (const auto& pr : both) {
    const sim::Recording& rec = *pr.first;
    const Run& r = *pr.second;
    std::size_t off = 0, art = 0, sat_rest = 0, sat = 0, sat_false = 0;
    for (std::size_t k = settle; k < rec.frames.size(); ++k) {
      for (std::size_t ch = 0; ch < kChannels; ++ch) {
        const QualityFlags& f = r.flags[k][ch];
        off += f.electrode_off ? 1 : 0;
        art += f.artifact ? 1 : 0;
        if (!f.saturation) continue;
        ++sat;
        if (rec.labels[k] == 0) ++sat_rest;
        // A true positive has rail hits within the window that raised it or the one it is held over.
        bool hit = false;
        for (std::size_t j = k >= 60 ? k - 60 : 0; j <= k; ++j)
          hit = hit || rec.frames[j][ch] <= -128 || rec.frames[j][ch] >= 127;
        sat_false += hit ? 0 : 1;
      }
    }
    INFO(rec.format << " " << rec.frames.size());
    MESSAGE("flags: electrode_off " << off << " artifact " << art << " saturation " << sat << " (at rest " << sat_rest
                                    << ", without rail hits " << sat_false << ") channel-frames");
    CHECK(off == 0);
    CHECK(art == 0);
    CHECK(sat_false == 0);
  }
}

TEST_CASE("malformed recordings are refused with the file and line") {
  const auto path = std::filesystem::temp_directory_path() / "tonus-bad-recording.txt";
  const auto try_load = [&](const std::string& text) {
    std::ofstream(path) << text;
    sim::Recording rec;
    std::string error;
    const bool ok = sim::load_recording(path.string(), rec, error);
    return std::make_pair(ok, error);
  };
  auto [ok, error] = try_load("1,2,3\n");
  CHECK_FALSE(ok);
  CHECK(error.find(":1:") != std::string::npos);
  std::tie(ok, error) = try_load("# Sampling Rate (Hz):= 1000.00\n2048\n5000\n");
  CHECK_FALSE(ok);
  CHECK(error.find(":3:") != std::string::npos);
  std::tie(ok, error) = try_load("# no rate header\n2048\n");
  CHECK_FALSE(ok);
  CHECK(error.find("Sampling Rate") != std::string::npos);
  std::tie(ok, error) = try_load("1,2,3,4,5,6,7,300,0\n");
  CHECK_FALSE(ok);
  std::tie(ok, error) = try_load("");
  CHECK_FALSE(ok);
  std::filesystem::remove(path);
  sim::Recording rec;
  CHECK_FALSE(sim::load_recording("/nonexistent/emg.txt", rec, error));
  CHECK(error.find("cannot open") != std::string::npos);
}
