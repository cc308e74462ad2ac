#include "tonus/firmware/device.hpp"

#include <cmath>

#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/wire.hpp"

// The commit the firmware was built from (firmware/CMakeLists.txt), 0 if unknown.
#ifndef TONUS_BUILD_ID
#define TONUS_BUILD_ID 0
#endif

namespace tonus::fw {

namespace {

constexpr std::uint32_t kBuildId = static_cast<std::uint32_t>(TONUS_BUILD_ID);

using proto::Status;

constexpr std::uint16_t bit(std::size_t k) { return static_cast<std::uint16_t>(1U << k); }

// Envelope in reference units as Q1.15 (32768 == reference), saturating.
std::uint16_t to_q15(float v) {
  const float scaled = v * static_cast<float>(proto::kEnvelopeOne);
  if (!(scaled > 0.0F)) return 0;
  if (scaled >= 65535.0F) return 0xFFFF;
  return static_cast<std::uint16_t>(std::lround(scaled));
}

// Offsets of the enum fields inside the DeviceConfig wire form, to name the
// field when its decoder refuses an enum value.
constexpr std::size_t kEnvelopeModeOffset = 10;
constexpr std::size_t kMeasureOffset = 21;
constexpr std::size_t kCurveOffset = 26;

proto::ConfigField undecodable_field(std::span<const std::uint8_t> body) {
  if (body[kEnvelopeModeOffset] > static_cast<std::uint8_t>(proto::EnvelopeMode::moving_rms)) {
    return proto::ConfigField::envelope_mode;
  }
  if (body[kMeasureOffset] > static_cast<std::uint8_t>(proto::CoContractionMeasure::cci)) {
    return proto::ConfigField::measure;
  }
  if (body[kCurveOffset] > static_cast<std::uint8_t>(proto::LevelCurve::power)) return proto::ConfigField::curve;
  return proto::ConfigField::none;
}

}  // namespace

proto::ConfigField check_device_config(const proto::DeviceConfig& cfg, const FrontEnd& fe) {
  const proto::ConfigField f = proto::check_config(cfg, static_cast<std::uint8_t>(kGroups));
  if (f != proto::ConfigField::none) return f;
  if (!fe.supports_rate(cfg.sample_rate_hz)) return proto::ConfigField::sample_rate_hz;
  for (std::size_t p = kPairs; p < proto::kMaxPairs; ++p) {
    if (cfg.pair_group[p] != proto::kPairUnused) return proto::ConfigField::pair_group;
  }
  return proto::ConfigField::none;
}

proto::DeviceConfig default_config(const FrontEnd& fe) {
  proto::DeviceConfig cfg{};
  std::uint16_t rate = fe.min_rate_hz;
  for (std::uint32_t r = fe.min_rate_hz; r <= fe.max_rate_hz && r <= 2000; r += fe.rate_step_hz) {
    if (fe.supports_rate(static_cast<std::uint16_t>(r))) rate = static_cast<std::uint16_t>(r);
    if (fe.rate_step_hz == 0) break;
  }
  cfg.sample_rate_hz = rate;
  if (cfg.report_rate_hz > rate) cfg.report_rate_hz = rate;
  const std::uint32_t nyquist_dhz = static_cast<std::uint32_t>(rate) * 5U;
  if (cfg.lowpass_dhz >= nyquist_dhz) cfg.lowpass_dhz = 0;
  if (cfg.highpass_dhz >= nyquist_dhz) cfg.highpass_dhz = 0;
  return cfg;
}

void Device::boot() {
  board_.led.show(hal::LedPattern::booting);
  front_end_ = board_.emg.front_end();
  boot_us_ = board_.clock.now_us();
  watchdog_reset_ = board_.watchdog.caused_last_reset();
  stats_ = proto::DeviceStats{};
  stats_.watchdog_resets = watchdog_reset_ ? 1 : 0;
  sequence_ = 0;
  block_seen_ = false;
  block_lost_pending_ = false;
  stale_blocks_ = 0;
  reset_pending_ = false;
  reset_issued_ = false;
  reset_deadline_us_ = 0;
  to_bootloader_ = false;
  reset_cause_ = board_.system.reset_cause();
  faults_ = FaultLog{};
  calibrator_ = Calibrator{};

  Persisted p{default_config(front_end_), default_calibration(front_end_)};
  Persisted stored{};
  load_result_ = load_persisted(board_.storage, stored);
  boot_count_ = 0;
  if (load_result_ == LoadResult::loaded) {
    // A record from a board with another front end (or a bug) must not brick the band.
    const proto::ConfigField bad = check_device_config(stored.config, front_end_);
    if (bad == proto::ConfigField::none) {
      p = stored;
    } else {
      load_result_ = LoadResult::corrupt;
      fault(proto::FaultCode::config_rejected, static_cast<std::uint16_t>(bad));
    }
  } else if (load_result_ != LoadResult::empty) {
    fault(proto::FaultCode::storage_corrupt, static_cast<std::uint16_t>(load_result_));
  }
  if (watchdog_reset_) fault(proto::FaultCode::watchdog_reset, 0);
  // The boot count rides in the record: counted where the storage holds this
  // firmware's record or nothing. Anything else is left as found (a newer
  // firmware's record after a downgrade, a corrupt one to look at).
  if (load_result_ == LoadResult::loaded || load_result_ == LoadResult::empty) {
    p.boot_count = (load_result_ == LoadResult::loaded ? stored.boot_count : 0U) + 1U;
    if (save_persisted(board_.storage, p)) {
      boot_count_ = p.boot_count;
    } else {
      fault(proto::FaultCode::storage_error, 0);
    }
  }
  calibration_ = p.calibration;
  config_dirty_ = false;
  apply_config(p.config, true);
  next_heartbeat_us_ = boot_us_;
  update_led();
}

void Device::apply_config(const proto::DeviceConfig& cfg, bool restart_sampler) {
  const bool rate_changed = cfg.sample_rate_hz != config_.sample_rate_hz;
  config_ = cfg;
  chain_ = design_chain(cfg);
  quality_model_ = design_quality(front_end_, chain_.sample_rate_hz, chain_.notch_count > 0);
  level_model_ = design_levels(cfg);
  for (ChannelState& c : channels_) reset(c);
  for (QualityState& q : quality_) q = QualityState{};
  level_state_ = LevelState{};
  envelopes_.fill(0.0F);
  report_phase_ = 0;
  can_requests_ = proto::can::Reassembler(proto::can::Function::request, cfg.can_node_id, cfg.can_id_base);
  if (restart_sampler || rate_changed) {
    sampler_ok_ = board_.emg.start(cfg.sample_rate_hz);
    block_seen_ = false;  // a restarted sampler may restart its sequence
    sampler_since_us_ = board_.clock.now_us();
    stall_restarts_ = 0;
    sampler_stalled_ = false;
  }
}

std::uint16_t Device::status_bits() const {
  std::uint16_t s = 0;
  const std::uint16_t used = [&] {
    std::uint16_t m = 0;
    for (std::size_t p = 0; p < kPairs; ++p) {
      if (config_.pair_group[p] != proto::kPairUnused) m = static_cast<std::uint16_t>(m | bit(2 * p) | bit(2 * p + 1));
    }
    return m;
  }();
  if (used != 0 && (calibration_.calibrated_mask() & used) == used) s |= proto::status_bit::calibrated;
  if (calibrator_.running()) s |= proto::status_bit::calibrating;
  if (watchdog_reset_) s |= proto::status_bit::watchdog_reset;
  if (config_dirty_) s |= proto::status_bit::config_dirty;
  if (block_lost_pending_) s |= proto::status_bit::block_lost;
  return s;
}

proto::DeviceStats Device::stats() const {
  proto::DeviceStats s = stats_;
  s.uptime_ms = static_cast<std::uint32_t>((board_.clock.now_us() - boot_us_) / 1000U);
  return s;
}

void Device::poll() {
  const std::uint64_t now = board_.clock.now_us();
  if (board_.hid != nullptr) board_.hid->service();
  if (reset_pending_) {
    // Nothing new is taken in or sent while the answer to `reset` drains.
    reboot_when_drained(now);
    board_.watchdog.kick();
    return;
  }
  poll_hid();
  poll_can();
  while (const hal::SampleBlock* block = board_.emg.acquire()) {
    process_block(*block, now);
    board_.emg.release();
  }
  calibrator_.on_tick(board_.clock.now_us());
  if (calibrator_.take_changed()) config_dirty_ = true;
  check_sampler(board_.clock.now_us());
  send_heartbeat(board_.clock.now_us());
  update_led();
  // A stalled sampler is a fault the main loop cannot fix: the watchdog resets the chip.
  if (!sampler_stalled_) board_.watchdog.kick();
}

void Device::check_sampler(std::uint64_t now_us) {
  if (!sampler_ok_ || sampler_stalled_ || now_us < sampler_since_us_ + kSamplerStallUs) return;
  if (stall_restarts_ == 0) {
    ++stall_restarts_;
    sampler_ok_ = board_.emg.start(config_.sample_rate_hz);
    block_seen_ = false;
    sampler_since_us_ = now_us;
    fault(proto::FaultCode::sampler_restarted, stall_restarts_);
    return;
  }
  sampler_stalled_ = true;
  fault(proto::FaultCode::sampler_stalled, 0);
}

std::uint8_t Device::boot_epoch() const {
  // The board's own epoch, else one from the persisted boot count.
  const std::uint8_t board = board_.system.boot_epoch();
  if (board != 0 || boot_count_ == 0) return board;
  return static_cast<std::uint8_t>(boot_count_ % 255U + 1U);
}

void Device::fault(proto::FaultCode code, std::uint16_t arg) {
  faults_.record(code, arg, static_cast<std::uint32_t>(board_.clock.now_us() / 1000U));
}

void Device::process_block(const hal::SampleBlock& block, std::uint64_t now_us) {
  if (block.frames == 0 || block.frames > kMaxBlockFrames) {
    ++stale_blocks_;  // a sampler bug, never worth a crash
    return;
  }
  if (block_seen_) {
    const auto ahead = static_cast<std::int32_t>(block.sequence - next_block_);
    if (ahead < 0) {
      ++stale_blocks_;  // already processed (or older): never twice
      return;
    }
    if (ahead > 0) {
      stats_.lost_blocks += static_cast<std::uint32_t>(ahead);
      block_lost_pending_ = true;
      fault(proto::FaultCode::blocks_lost, static_cast<std::uint16_t>(ahead < 0xFFFF ? ahead : 0xFFFF));
    }
  }
  block_seen_ = true;
  next_block_ = block.sequence + 1;
  sampler_since_us_ = now_us;
  stall_restarts_ = 0;
  sampler_stalled_ = false;

  const std::uint32_t rate = config_.sample_rate_hz;
  const std::uint64_t end_us = block.first_sample_us + static_cast<std::uint64_t>(block.frames) * 1000000U / rate;
  // Late: processed more than two block lengths after its last sample.
  const std::uint64_t block_us = end_us - block.first_sample_us;
  if (now_us > end_us + 2 * block_us + 1000U) ++stats_.late_blocks;

  for (std::size_t f = 0; f < block.frames; ++f) {
    const std::uint64_t t = block.first_sample_us + static_cast<std::uint64_t>(f) * 1000000U / rate;
    process_frame(&block.samples[f * kChannels], t);
  }
}

void Device::process_frame(const std::int16_t* frame, std::uint64_t t_us) {
  std::uint16_t off = 0;
  for (std::size_t ch = 0; ch < kChannels; ++ch) {
    ChainTaps taps;
    envelopes_[ch] = chain_step(chain_, channels_[ch], static_cast<float>(frame[ch]), taps);
    quality_step(quality_model_, quality_[ch], frame[ch], taps);
    if (quality_[ch].held.electrode_off) off = static_cast<std::uint16_t>(off | bit(ch));
  }
  if (calibrator_.running()) {
    for (std::size_t p = 0; p < kPairs; ++p) {
      cocontraction_[p] = cocontraction(config_.measure, normalise(calibration_, 2 * p, envelopes_[2 * p]),
                                        normalise(calibration_, 2 * p + 1, envelopes_[2 * p + 1]));
    }
    calibrator_.on_frame(envelopes_, off, cocontraction_, calibration_);
  }
  report_phase_ += config_.report_rate_hz;
  if (report_phase_ >= config_.sample_rate_hz) {
    report_phase_ -= config_.sample_rate_hz;
    emit_report(t_us);
  }
}

void Device::emit_report(std::uint64_t t_us) {
  proto::StreamMessage m{};
  m.sequence = sequence_++;
  m.device_time_us = static_cast<std::uint32_t>(t_us);
  m.group_count = static_cast<std::uint8_t>(kGroups);
  m.channel_count = static_cast<std::uint8_t>(kChannels);
  m.boot_epoch = boot_epoch();

  std::array<float, kPairs> c{};
  for (std::size_t ch = 0; ch < kChannels; ++ch) {
    const float n = normalise(calibration_, ch, envelopes_[ch]);
    m.envelopes[ch] = to_q15(n);
    const QualityFlags& q = quality_[ch].held;
    if (q.electrode_off) m.electrode_off = static_cast<std::uint16_t>(m.electrode_off | bit(ch));
    if (q.saturation) m.saturation = static_cast<std::uint16_t>(m.saturation | bit(ch));
    if (q.artifact) m.artifact = static_cast<std::uint16_t>(m.artifact | bit(ch));
  }
  for (std::size_t p = 0; p < kPairs; ++p) {
    const bool off = (m.electrode_off & (bit(2 * p) | bit(2 * p + 1))) != 0;
    // A lifted electrode reads hum, not effort: its pair relaxes instead of stiffening.
    // Levels use the level envelope: fast after a change of effort (level_envelope.hpp).
    const float flexor = level_envelope(chain_, channels_[2 * p]);
    const float extensor = level_envelope(chain_, channels_[2 * p + 1]);
    c[p] = off ? 0.0F
               : cocontraction(config_.measure, normalise(calibration_, 2 * p, flexor),
                               normalise(calibration_, 2 * p + 1, extensor)) /
                     calibration_.cocontraction[p];
  }
  std::array<std::uint16_t, kGroups> groups{};
  levels_step(level_model_, level_state_, c, groups);
  for (std::size_t g = 0; g < kGroups; ++g) m.levels[g] = groups[g];
  m.status = status_bits();
  block_lost_pending_ = false;
  report_ = m;
  ++stats_.reports_sent;
  if (observer_ != nullptr) observer_(observer_context_, m);

  if (board_.hid != nullptr && board_.hid->connected()) {
    proto::hid::Report r{};
    if (proto::hid::pack_stream(m, r) != proto::Error::ok || !board_.hid->send_input(r)) ++stats_.tx_dropped;
  }
  if (board_.can != nullptr) {
    const bool with_env = config_.can_envelope_divider != 0 && m.sequence % config_.can_envelope_divider == 0;
    std::array<proto::CanFrame, proto::can::kMaxStreamFrames> frames{};
    std::size_t count = 0;
    if (proto::can::encode_stream(m, config_.can_node_id, with_env, frames, count, config_.can_id_base) !=
        proto::Error::ok) {
      ++stats_.tx_dropped;
    } else {
      for (std::size_t k = 0; k < count; ++k) {
        if (!board_.can->send(frames[k])) {
          ++stats_.tx_dropped;  // the rest of the cycle would be incomplete anyway
          fault(proto::FaultCode::can_down, static_cast<std::uint16_t>(count - k));
          break;
        }
      }
    }
  }
}

void Device::poll_hid() {
  if (board_.hid == nullptr) return;
  proto::hid::Report r{};
  std::size_t length = 0;
  while (board_.hid->receive_output(r, length)) {
    const std::uint64_t rx = board_.clock.now_us();
    if (length < 2 || length > r.size() || r[0] != proto::hid::kReportIdCommand) {
      ++stats_.commands_rejected;  // not a command report: nothing to answer
      continue;
    }
    receive(std::span<const std::uint8_t>(r).subspan(1, length - 1), Link::hid, rx);
    if (reset_pending_) return;
  }
}

void Device::poll_can() {
  if (board_.can == nullptr) return;
  proto::CanFrame frame{};
  while (board_.can->receive(frame)) {
    bool complete = false;
    if (can_requests_.push(frame, complete) != proto::Error::ok) {
      ++stats_.commands_rejected;
      continue;
    }
    if (!complete) continue;
    receive(can_requests_.message(), Link::can, board_.clock.now_us());
    if (reset_pending_) return;
  }
}

void Device::receive(std::span<const std::uint8_t> message, Link link, std::uint64_t rx_us) {
  proto::Request req{};
  const proto::Error e = proto::decode_request(message, req);
  proto::Response rsp{};
  // The answer leaves from the id the request was sent to, even when the
  // request changes it (set_config of can_node_id or can_id_base): the host waits there.
  const std::uint8_t answer_node = config_.can_node_id;
  const std::uint32_t answer_base = config_.can_id_base;
  if (e == proto::Error::ok) {
    handle(req, rx_us, rsp);
  } else {
    ++stats_.commands_rejected;
    // Answer what can be answered so the host does not wait for a timeout;
    // header bytes are version, opcode, token.
    if (message.size() < 3 || (message[1] & proto::kResponseBit) != 0) return;
    proto::Request header{};
    header.opcode = static_cast<proto::Opcode>(message[1]);
    header.token = message[2];
    Status s = Status::bad_length;
    if (e == proto::Error::bad_crc) s = Status::bad_crc;
    if (e == proto::Error::bad_version) s = Status::bad_version;
    rsp = proto::make_response(header, s);
  }
  reply(rsp, link, answer_node, answer_base);
  after_reply(link);
}

void Device::reply(const proto::Response& rsp, Link link, std::uint8_t can_node, std::uint32_t can_id_base) {
  if (link == Link::hid) {
    proto::hid::Report r{};
    if (proto::hid::pack_response(rsp, r) != proto::Error::ok || !board_.hid->send_input(r)) ++stats_.tx_dropped;
    return;
  }
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  std::array<proto::CanFrame, proto::can::kMaxSegments> frames{};
  std::size_t count = 0;
  if (proto::encode_response(rsp, bytes, n) != proto::Error::ok ||
      proto::can::segment(std::span<const std::uint8_t>(bytes).first(n), proto::can::Function::response, can_node,
                          frames, count, can_id_base) != proto::Error::ok) {
    ++stats_.tx_dropped;
    return;
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (!board_.can->send(frames[k])) {
      ++stats_.tx_dropped;
      return;
    }
  }
}

void Device::after_reply(Link) {
  if (!reset_pending_ || reset_deadline_us_ != 0) return;
  reset_deadline_us_ = board_.clock.now_us() + kResetDrainUs;
  reboot_when_drained(board_.clock.now_us());
}

void Device::reboot_when_drained(std::uint64_t now_us) {
  if (reset_issued_) return;
  // The answer to `reset` must leave first: over HID it waits for the host's
  // next IN poll, over CAN for the transmit queue (a reset cuts both short).
  const bool hid_done = board_.hid == nullptr || !board_.hid->connected() || board_.hid->idle();
  const bool can_done = board_.can == nullptr || board_.can->idle();
  if (!(hid_done && can_done) && now_us < reset_deadline_us_) return;
  reset_issued_ = true;
  if (to_bootloader_) {
    board_.system.enter_bootloader();
    return;
  }
  if (reset_kind_ == proto::ResetKind::factory_defaults) erase_persisted(board_.storage);
  board_.system.reset();
}

void Device::handle(const proto::Request& req, std::uint64_t rx_us, proto::Response& rsp) {
  using proto::Opcode;
  switch (req.opcode) {
    case Opcode::get_device_info: {
      proto::DeviceInfo info{};
      info.firmware_major = kFirmwareMajor;
      info.firmware_minor = kFirmwareMinor;
      info.firmware_patch = kFirmwarePatch;
      info.serial = board_.serial;
      info.hardware_revision = board_.hardware_revision;
      info.channel_count = static_cast<std::uint8_t>(kChannels);
      info.group_count = static_cast<std::uint8_t>(kGroups);
      info.pair_count = static_cast<std::uint8_t>(kPairs);
      info.sample_rate_hz = config_.sample_rate_hz;
      info.report_rate_hz = config_.report_rate_hz;
      info.pair_group = config_.pair_group;
      info.transports = static_cast<std::uint8_t>((board_.hid != nullptr ? proto::transport_bit::usb_hid : 0) |
                                                  (board_.can != nullptr ? proto::transport_bit::can : 0));
      info.protocol_minor = proto::kProtocolMinor;
      info.features = proto::feature_bit::fault_log | (boot_epoch() != 0 ? proto::feature_bit::boot_epoch : 0U) |
                      (board_.system.has_bootloader() ? proto::feature_bit::bootloader : 0U);
      info.build_id = kBuildId;
      info.boot_count = boot_count_;
      info.reset_cause = reset_cause_;
      proto::make_response(req, Status::ok, info, rsp);
      return;
    }
    case Opcode::time_sync: {
      proto::TimeSyncRequest ts{};
      if (proto::read_payload(req, ts) != proto::Error::ok) {
        rsp = proto::make_response(req, Status::bad_length);
        ++stats_.commands_rejected;
        return;
      }
      proto::TimeSyncResponse out{};
      out.host_time_us = ts.host_time_us;
      out.device_rx_us = rx_us;
      const std::uint64_t tx = board_.clock.now_us();
      out.device_tx_us = tx < rx_us ? rx_us : tx;
      proto::make_response(req, Status::ok, out, rsp);
      return;
    }
    case Opcode::get_stats: proto::make_response(req, Status::ok, stats(), rsp); return;
    case Opcode::get_log: {
      proto::FaultLog log{};
      faults_.take(log);
      proto::make_response(req, Status::ok, log, rsp);
      return;
    }
    case Opcode::enter_bootloader:
      if (!board_.system.has_bootloader()) {
        ++stats_.commands_rejected;
        rsp = proto::make_response(req, Status::wrong_state);
        return;
      }
      reset_pending_ = true;
      to_bootloader_ = true;
      rsp = proto::make_response(req, Status::ok);
      return;
    case Opcode::calibration_start: on_calibration_start(req, rsp, rx_us); return;
    case Opcode::calibration_abort: {
      const Status s = calibrator_.abort();
      if (s != Status::ok) ++stats_.commands_rejected;
      proto::make_response(req, s, calibrator_.status(calibration_), rsp);
      return;
    }
    case Opcode::calibration_status:
      proto::make_response(req, Status::ok, calibrator_.status(calibration_), rsp);
      return;
    case Opcode::get_config: proto::make_response(req, Status::ok, config_, rsp); return;
    case Opcode::set_config: on_set_config(req, rsp); return;
    case Opcode::save_config: {
      if (calibrator_.running()) {
        ++stats_.commands_rejected;
        rsp = proto::make_response(req, Status::wrong_state);
        return;
      }
      const bool ok = save_persisted(board_.storage, Persisted{config_, calibration_, boot_count_});
      if (ok) config_dirty_ = false;
      if (!ok) fault(proto::FaultCode::storage_error, 0);
      rsp = proto::make_response(req, ok ? Status::ok : Status::storage_error);
      return;
    }
    case Opcode::reset: {
      proto::ResetRequest r{};
      const proto::Error e = proto::read_payload(req, r);
      if (e != proto::Error::ok) {
        ++stats_.commands_rejected;
        rsp = proto::make_response(req, e == proto::Error::bad_length ? Status::bad_length : Status::bad_value);
        return;
      }
      reset_pending_ = true;
      reset_kind_ = r.kind;
      rsp = proto::make_response(req, Status::ok);
      return;
    }
  }
  ++stats_.commands_rejected;
  rsp = proto::make_response(req, Status::unknown_opcode);
}

void Device::on_calibration_start(const proto::Request& req, proto::Response& rsp, std::uint64_t now_us) {
  proto::CalibrationStart start{};
  const proto::Error e = proto::read_payload(req, start);
  Status s = Status::ok;
  if (e == proto::Error::bad_length || e == proto::Error::truncated) {
    s = Status::bad_length;
  } else if (e != proto::Error::ok) {
    s = Status::bad_value;
  } else {
    s = calibrator_.start(start, chain_.sample_rate_hz, now_us);
  }
  if (s != Status::ok) ++stats_.commands_rejected;
  proto::make_response(req, s, calibrator_.status(calibration_), rsp);
}

void Device::on_set_config(const proto::Request& req, proto::Response& rsp) {
  proto::DeviceConfig cfg{};
  const proto::Error e = proto::read_payload(req, cfg);
  proto::SetConfigResult result{};
  Status s = Status::ok;
  if (e == proto::Error::bad_length || e == proto::Error::truncated) {
    s = Status::bad_length;
  } else if (e != proto::Error::ok) {
    s = Status::bad_value;
    result.rejected = undecodable_field(req.body());
  } else if (calibrator_.running() && !(cfg == config_)) {
    s = Status::wrong_state;  // a calibration in progress would mix two chains
  } else {
    result.rejected = check_device_config(cfg, front_end_);
    if (result.rejected != proto::ConfigField::none) s = Status::bad_value;
  }
  if (s == Status::ok && !(cfg == config_)) {
    apply_config(cfg, false);
    config_dirty_ = true;
  }
  if (s != Status::ok) ++stats_.commands_rejected;
  proto::make_response(req, s, result, rsp);
}

void Device::send_heartbeat(std::uint64_t now_us) {
  if (board_.can == nullptr || now_us < next_heartbeat_us_) return;
  next_heartbeat_us_ = now_us + kHeartbeatPeriodUs;
  proto::can::Heartbeat hb{};
  hb.state = !sampler_ok_ || sampler_stalled_ ? proto::can::NodeState::fault
             : calibrator_.running()          ? proto::can::NodeState::calibrating
                                              : proto::can::NodeState::running;
  hb.status = status_bits();
  hb.uptime_ms = static_cast<std::uint32_t>((now_us - boot_us_) / 1000U);
  if (!board_.can->send(proto::can::encode_heartbeat(hb, config_.can_node_id, config_.can_id_base))) {
    ++stats_.tx_dropped;
  }
}

void Device::update_led() {
  hal::LedPattern p = hal::LedPattern::running;
  if (!sampler_ok_ || sampler_stalled_) {
    p = hal::LedPattern::fault;
  } else if (calibrator_.running()) {
    p = hal::LedPattern::calibrating;
  } else if ((status_bits() & proto::status_bit::calibrated) == 0) {
    p = hal::LedPattern::uncalibrated;
  }
  board_.led.show(p);
}

}  // namespace tonus::fw
