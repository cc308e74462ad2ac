#include "tonus/protocol/payloads.hpp"

namespace tonus::proto {

namespace {

template <class Enum>
Error read_enum(ByteReader& r, Enum& out, std::uint8_t first, std::uint8_t last) {
  const std::uint8_t v = r.u8();
  if (!r.ok()) return r.error();
  if (v < first || v > last) return Error::bad_value;
  out = static_cast<Enum>(v);
  return Error::ok;
}

template <class Enum>
constexpr std::uint8_t raw(Enum e) {
  return static_cast<std::uint8_t>(e);
}

}  // namespace

void DeviceInfo::write(ByteWriter& w) const {
  w.u8(firmware_major);
  w.u8(firmware_minor);
  w.u8(firmware_patch);
  w.u8(protocol_version);
  w.u64(serial);
  w.u8(hardware_revision);
  w.u8(channel_count);
  w.u8(group_count);
  w.u8(pair_count);
  w.u16(sample_rate_hz);
  w.u16(report_rate_hz);
  w.bytes(pair_group);
  w.u8(transports);
  w.u8(protocol_minor);
  w.u32(features);
  w.u32(build_id);
  w.u32(boot_count);
  w.u8(static_cast<std::uint8_t>(reset_cause));
}

Error DeviceInfo::read(ByteReader& r) {
  firmware_major = r.u8();
  firmware_minor = r.u8();
  firmware_patch = r.u8();
  protocol_version = r.u8();
  serial = r.u64();
  hardware_revision = r.u8();
  channel_count = r.u8();
  group_count = r.u8();
  pair_count = r.u8();
  sample_rate_hz = r.u16();
  report_rate_hz = r.u16();
  r.bytes(pair_group);
  transports = r.u8();
  if (!r.ok()) return r.error();
  if (r.remaining() >= kWireSize - kMinWireSize) {  // minor 1 fields
    protocol_minor = r.u8();
    features = r.u32();
    build_id = r.u32();
    boot_count = r.u32();
    const std::uint8_t cause = r.u8();
    if (cause > static_cast<std::uint8_t>(ResetCause::low_power)) return Error::bad_value;
    reset_cause = static_cast<ResetCause>(cause);
  }
  if (channel_count < 1 || channel_count > kMaxChannels) return Error::bad_length;
  if (group_count < 1 || group_count > kMaxGroups) return Error::bad_length;
  if (pair_count > kMaxPairs || pair_count * 2U > channel_count) return Error::bad_length;
  return Error::ok;
}

void TimeSyncRequest::write(ByteWriter& w) const { w.u64(host_time_us); }

Error TimeSyncRequest::read(ByteReader& r) {
  host_time_us = r.u64();
  return r.error();
}

void TimeSyncResponse::write(ByteWriter& w) const {
  w.u64(host_time_us);
  w.u64(device_rx_us);
  w.u64(device_tx_us);
}

Error TimeSyncResponse::read(ByteReader& r) {
  host_time_us = r.u64();
  device_rx_us = r.u64();
  device_tx_us = r.u64();
  if (!r.ok()) return r.error();
  // The device cannot answer before it received the request.
  return device_tx_us >= device_rx_us ? Error::ok : Error::bad_value;
}

void DeviceStats::write(ByteWriter& w) const {
  w.u32(uptime_ms);
  w.u32(reports_sent);
  w.u32(lost_blocks);
  w.u32(late_blocks);
  w.u32(tx_dropped);
  w.u16(commands_rejected);
  w.u16(watchdog_resets);
}

Error DeviceStats::read(ByteReader& r) {
  uptime_ms = r.u32();
  reports_sent = r.u32();
  lost_blocks = r.u32();
  late_blocks = r.u32();
  tx_dropped = r.u32();
  commands_rejected = r.u16();
  watchdog_resets = r.u16();
  return r.error();
}

void CalibrationStart::write(ByteWriter& w) const {
  w.u8(raw(phase));
  w.u16(channel_mask);
  w.u16(duration_ms);
}

Error CalibrationStart::read(ByteReader& r) {
  if (Error e = read_enum(r, phase, raw(CalibrationPhase::rest), raw(CalibrationPhase::co_contraction));
      e != Error::ok) {
    return e;
  }
  channel_mask = r.u16();
  duration_ms = r.u16();
  if (!r.ok()) return r.error();
  if (channel_mask == 0) return Error::bad_value;
  if (duration_ms < kMinDurationMs || duration_ms > kMaxDurationMs) return Error::bad_value;
  return Error::ok;
}

void CalibrationStatus::write(ByteWriter& w) const {
  w.u8(raw(state));
  w.u8(phase);
  w.u8(progress_pct);
  w.u16(calibrated_mask);
  w.u8(phases_done);
}

Error CalibrationStatus::read(ByteReader& r) {
  if (Error e = read_enum(r, state, raw(CalibrationState::idle), raw(CalibrationState::failed)); e != Error::ok) {
    return e;
  }
  phase = r.u8();
  progress_pct = r.u8();
  calibrated_mask = r.u16();
  phases_done = r.u8();
  if (!r.ok()) return r.error();
  if (phase > raw(CalibrationPhase::co_contraction) || progress_pct > 100) return Error::bad_value;
  return Error::ok;
}

void DeviceConfig::write(ByteWriter& w) const {
  w.u16(sample_rate_hz);
  w.u16(report_rate_hz);
  w.u16(highpass_dhz);
  w.u16(lowpass_dhz);
  w.u8(notch_hz);
  w.u8(notch_harmonics);
  w.u8(raw(envelope_mode));
  w.u16(envelope_tau_ms);
  w.bytes(pair_group);
  w.u8(raw(measure));
  w.u16(dead_band);
  w.u16(hysteresis);
  w.u8(raw(curve));
  w.u16(curve_exponent_milli);
  w.u8(can_node_id);
  w.u8(can_envelope_divider);
  w.u32(can_id_base);
}

Error DeviceConfig::read(ByteReader& r) {
  sample_rate_hz = r.u16();
  report_rate_hz = r.u16();
  highpass_dhz = r.u16();
  lowpass_dhz = r.u16();
  notch_hz = r.u8();
  notch_harmonics = r.u8();
  if (Error e = read_enum(r, envelope_mode, raw(EnvelopeMode::linear), raw(EnvelopeMode::moving_rms)); e != Error::ok) {
    return e;
  }
  envelope_tau_ms = r.u16();
  r.bytes(pair_group);
  if (Error e = read_enum(r, measure, raw(CoContractionMeasure::min_normalised), raw(CoContractionMeasure::cci));
      e != Error::ok) {
    return e;
  }
  dead_band = r.u16();
  hysteresis = r.u16();
  if (Error e = read_enum(r, curve, raw(LevelCurve::linear), raw(LevelCurve::power)); e != Error::ok) return e;
  curve_exponent_milli = r.u16();
  can_node_id = r.u8();
  can_envelope_divider = r.u8();
  if (!r.ok()) return r.error();
  if (r.remaining() >= kWireSize - kMinWireSize) can_id_base = r.u32();  // minor 1
  return r.error();
}

const char* to_string(ConfigField f) {
  switch (f) {
    case ConfigField::none: return "none";
    case ConfigField::sample_rate_hz: return "sample_rate_hz";
    case ConfigField::report_rate_hz: return "report_rate_hz";
    case ConfigField::highpass_dhz: return "highpass_dhz";
    case ConfigField::lowpass_dhz: return "lowpass_dhz";
    case ConfigField::notch_hz: return "notch_hz";
    case ConfigField::notch_harmonics: return "notch_harmonics";
    case ConfigField::envelope_mode: return "envelope_mode";
    case ConfigField::envelope_tau_ms: return "envelope_tau_ms";
    case ConfigField::pair_group: return "pair_group";
    case ConfigField::measure: return "measure";
    case ConfigField::dead_band: return "dead_band";
    case ConfigField::hysteresis: return "hysteresis";
    case ConfigField::curve: return "curve";
    case ConfigField::curve_exponent_milli: return "curve_exponent_milli";
    case ConfigField::can_node_id: return "can_node_id";
    case ConfigField::can_envelope_divider: return "can_envelope_divider";
    case ConfigField::can_id_base: return "can_id_base";
  }
  return "unknown field";
}

ConfigField check_config(const DeviceConfig& c, std::uint8_t group_count) {
  // Nyquist in decihertz: corners at or above it cannot be realised.
  const std::uint32_t nyquist_dhz = static_cast<std::uint32_t>(c.sample_rate_hz) * 5U;
  if (c.sample_rate_hz < 100 || c.sample_rate_hz > 4000) return ConfigField::sample_rate_hz;
  if (c.report_rate_hz < 1 || c.report_rate_hz > 1000 || c.report_rate_hz > c.sample_rate_hz) {
    return ConfigField::report_rate_hz;
  }
  if (c.highpass_dhz != 0 && (c.highpass_dhz < 10 || c.highpass_dhz >= nyquist_dhz)) return ConfigField::highpass_dhz;
  if (c.lowpass_dhz != 0 && (c.lowpass_dhz >= nyquist_dhz || c.lowpass_dhz <= c.highpass_dhz)) {
    return ConfigField::lowpass_dhz;
  }
  if (c.notch_hz != 0 && c.notch_hz != 50 && c.notch_hz != 60) return ConfigField::notch_hz;
  if (c.notch_harmonics < 1 || c.notch_harmonics > 8) return ConfigField::notch_harmonics;
  if (raw(c.envelope_mode) > raw(EnvelopeMode::moving_rms)) return ConfigField::envelope_mode;
  if (c.envelope_tau_ms < 5 || c.envelope_tau_ms > 2000) return ConfigField::envelope_tau_ms;
  for (std::uint8_t g : c.pair_group) {
    if (g != kPairUnused && g >= group_count) return ConfigField::pair_group;
  }
  if (raw(c.measure) > raw(CoContractionMeasure::cci)) return ConfigField::measure;
  if (c.dead_band > 0x7FFF) return ConfigField::dead_band;
  if (c.hysteresis > 0x4000) return ConfigField::hysteresis;
  if (raw(c.curve) > raw(LevelCurve::power)) return ConfigField::curve;
  if (c.curve_exponent_milli < 100 || c.curve_exponent_milli > 10000) return ConfigField::curve_exponent_milli;
  if (c.can_node_id > 31) return ConfigField::can_node_id;
  if (c.can_id_base % 0x800U != 0 || c.can_id_base > 0x1FFFF800U) return ConfigField::can_id_base;
  return ConfigField::none;
}

void SetConfigResult::write(ByteWriter& w) const { w.u8(raw(rejected)); }

Error SetConfigResult::read(ByteReader& r) {
  const std::uint8_t v = r.u8();
  if (!r.ok()) return r.error();
  if (v != raw(ConfigField::none) && v > raw(ConfigField::can_id_base)) return Error::bad_value;
  rejected = static_cast<ConfigField>(v);
  return Error::ok;
}

void ResetRequest::write(ByteWriter& w) const { w.u8(raw(kind)); }

Error ResetRequest::read(ByteReader& r) {
  return read_enum(r, kind, raw(ResetKind::reboot), raw(ResetKind::factory_defaults));
}

void FaultLog::write(ByteWriter& w) const {
  w.u8(count);
  w.u8(more);
  w.u16(dropped);
  for (const LogEntry& e : entries) {
    w.u32(e.time_ms);
    w.u8(static_cast<std::uint8_t>(e.code));
    w.u8(e.repeats);
    w.u16(e.arg);
  }
}

Error FaultLog::read(ByteReader& r) {
  count = r.u8();
  more = r.u8();
  dropped = r.u16();
  for (LogEntry& e : entries) {
    e.time_ms = r.u32();
    const std::uint8_t code = r.u8();
    e.repeats = r.u8();
    e.arg = r.u16();
    e.code = static_cast<FaultCode>(code);
  }
  if (!r.ok()) return r.error();
  if (count > kMaxEntries || more > 1) return Error::bad_value;
  // Unused slots are zero on the wire, so equal bytes give equal logs; used ones carry a known code.
  for (std::size_t k = 0; k < kMaxEntries; ++k) {
    const auto code = static_cast<std::uint8_t>(entries[k].code);
    if (k < count && (code < 1 || code > static_cast<std::uint8_t>(FaultCode::config_rejected)))
      return Error::bad_value;
    if (k >= count && (code != 0 || entries[k].time_ms != 0 || entries[k].arg != 0 || entries[k].repeats != 0)) {
      return Error::bad_value;
    }
  }
  return Error::ok;
}

}  // namespace tonus::proto
