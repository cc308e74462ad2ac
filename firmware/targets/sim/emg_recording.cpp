#include "emg_recording.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

namespace tonus::sim {

namespace {

bool parse_int(std::string_view s, int& v) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.empty()) return false;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, v);
  return ec == std::errc() && p == end;
}

std::string where(const std::string& path, std::size_t line) { return path + ":" + std::to_string(line) + ": "; }

bool load_biosppy(std::ifstream& in, const std::string& path, Recording& out, std::string& error) {
  out.format = "biosppy";
  out.source_channels = 1;
  out.front_end.rail_low = 0;
  out.front_end.rail_high = 4095;
  out.front_end.rail_margin = 2;
  std::string line;
  std::size_t n = 0;
  float rate = 0.0F;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line == "\r") continue;
    if (line[0] == '#') {
      const auto pos = line.find("Sampling Rate (Hz):=");
      if (pos != std::string::npos) {
        try {
          rate = std::stof(line.substr(pos + 20));
        } catch (...) {
          error = where(path, n) + "unreadable sampling rate";
          return false;
        }
      }
      continue;
    }
    int v = 0;
    if (!parse_int(line, v) || v < 0 || v > 4095) {
      error = where(path, n) + "expected one 12-bit sample, got '" + line + "'";
      return false;
    }
    Frame f{};
    f.fill(static_cast<std::int16_t>(v));
    out.frames.push_back(f);
  }
  if (!(rate >= 100.0F && rate <= 4000.0F)) {
    error = path + ": missing or unsupported '# Sampling Rate (Hz):=' header";
    return false;
  }
  out.sample_rate_hz = rate;
  return true;
}

bool load_myo(std::ifstream& in, const std::string& path, Recording& out, std::string& error) {
  out.format = "myo";
  out.source_channels = 8;
  out.sample_rate_hz = kMyoRateHz;
  out.front_end.rail_low = -128;
  out.front_end.rail_high = 127;
  out.front_end.rail_margin = 0;
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line == "\r") continue;
    std::array<int, 9> v{};
    std::size_t field = 0;
    std::string_view rest = line;
    bool ok = true;
    while (ok) {
      const auto comma = rest.find(',');
      if (field >= v.size() || !parse_int(rest.substr(0, comma), v[field])) ok = false;
      ++field;
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (!ok || field != 9) {
      error = where(path, n) + "expected 8 channels and a label, got '" + line + "'";
      return false;
    }
    Frame f{};
    for (std::size_t ch = 0; ch < 8; ++ch) {
      if (v[ch] < -128 || v[ch] > 127) {
        error = where(path, n) + "channel value outside int8";
        return false;
      }
      f[ch] = static_cast<std::int16_t>(v[ch]);
    }
    out.frames.push_back(f);
    out.labels.push_back(v[8]);
  }
  return true;
}

}  // namespace

bool load_recording(const std::string& path, Recording& out, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot open";
    return false;
  }
  out = Recording{};
  const int first = in.peek();
  const bool ok = first == '#' ? load_biosppy(in, path, out, error) : load_myo(in, path, out, error);
  if (!ok) return false;
  if (out.frames.empty()) {
    error = path + ": no samples";
    return false;
  }
  // The recording's own rate is the only one its "sampler" runs at.
  const auto rate = static_cast<std::uint16_t>(std::lround(out.sample_rate_hz));
  out.front_end.min_rate_hz = rate;
  out.front_end.max_rate_hz = rate;
  out.front_end.rate_step_hz = 0;
  // Scale the detector floors and the uncalibrated reference to the ADC span.
  const float span = out.front_end.span();
  out.front_end.default_reference = span * 0.05F;
  out.front_end.hum_floor = span * 0.01F;
  out.front_end.artifact_floor = span * 0.01F;
  return true;
}

}  // namespace tonus::sim
