// The device as a host sees it: commands and their bad-input paths, lost and
// repeated blocks, scripted faults, calibration over commands, CAN, reset.
#include <doctest/doctest.h>

#include <optional>

#include "fake_board.hpp"
#include "tonus/protocol/hid.hpp"

using namespace tonus;
using namespace tonus::fw;
using test::Bench;

namespace {

std::vector<std::uint8_t> hid_request(const proto::Request& req) {
  proto::hid::Report r{};
  REQUIRE(proto::hid::pack_request(req, r) == proto::Error::ok);
  return {r.begin(), r.end()};
}

template <class Payload>
proto::Request request(proto::Opcode op, std::uint8_t token, const Payload& p) {
  proto::Request req{};
  REQUIRE(proto::make_request(op, token, p, req) == proto::Error::ok);
  return req;
}

// Last response on the HID link, if any, removing it from the sent list.
std::optional<proto::Response> take_response(test::QueueHid& hid) {
  for (auto it = hid.sent.rbegin(); it != hid.sent.rend(); ++it) {
    if ((*it)[0] == proto::hid::kReportIdResponse) {
      proto::Response rsp{};
      REQUIRE(proto::hid::unpack_response(*it, rsp) == proto::Error::ok);
      hid.sent.clear();
      return rsp;
    }
  }
  hid.sent.clear();
  return std::nullopt;
}

proto::Response ask(Bench& b, Device& dev, const proto::Request& req) {
  b.hid.inbox.push_back(hid_request(req));
  b.step(dev);
  auto rsp = take_response(b.hid);
  REQUIRE(rsp.has_value());
  CHECK(rsp->token == req.token);
  return *rsp;
}

SynthSpec spec(Scenario s, float seconds) {
  SynthSpec sp;
  sp.scenario = s;
  sp.seconds = seconds;
  sp.seed = 3;
  return sp;
}

// Sends `req` over CAN to node `to` at `id_base`, runs two 1 ms blocks, and
// returns the response reassembled from node `from` at the same base, if any.
std::optional<proto::Response> ask_can(Bench& b, Device& dev, const proto::Request& req, std::uint8_t to,
                                       std::uint8_t from, std::uint32_t id_base = 0) {
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  REQUIRE(proto::encode_request(req, bytes, n) == proto::Error::ok);
  std::array<proto::CanFrame, proto::can::kMaxSegments> frames{};
  std::size_t count = 0;
  REQUIRE(proto::can::segment(std::span<const std::uint8_t>(bytes).first(n), proto::can::Function::request, to, frames,
                              count, id_base) == proto::Error::ok);
  for (std::size_t k = 0; k < count; ++k) b.can.inbox.push_back(frames[k]);
  b.can.sent.clear();
  b.step(dev);
  b.step(dev);
  proto::can::Reassembler reasm(proto::can::Function::response, from, id_base);
  std::optional<proto::Response> out;
  for (const proto::CanFrame& f : b.can.sent) {
    bool complete = false;
    if (reasm.push(f, complete) != proto::Error::ok || !complete) continue;
    proto::Response rsp{};
    REQUIRE(proto::decode_response(reasm.message(), rsp) == proto::Error::ok);
    out = rsp;
  }
  return out;
}

}  // namespace

TEST_CASE("boot on empty storage: defaults, not calibrated") {
  Bench b(spec(Scenario::rest, 1.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  CHECK(dev.boot_load_result() == LoadResult::empty);
  CHECK(dev.config() == default_config(b.gen.front_end()));
  CHECK((dev.status_bits() & proto::status_bit::calibrated) == 0);
  CHECK(b.led.pattern() == hal::LedPattern::uncalibrated);
  b.run_for(dev, 0.5F);
  CHECK(dev.reports() == 250);  // the default 500 Hz report rate
  CHECK(b.watchdog.kicks() > 0);
}

TEST_CASE("commands: device info, time sync, stats, config") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.1F);

  proto::Response rsp = ask(b, dev, proto::make_request(proto::Opcode::get_device_info, 1));
  CHECK(rsp.status == proto::Status::ok);
  proto::DeviceInfo info{};
  REQUIRE(proto::read_payload(rsp, info) == proto::Error::ok);
  CHECK(info.channel_count == 8);
  CHECK(info.group_count == 4);
  CHECK(info.serial == 42);
  CHECK(info.transports == (proto::transport_bit::usb_hid | proto::transport_bit::can));

  rsp = ask(b, dev, request(proto::Opcode::time_sync, 2, proto::TimeSyncRequest{123456789}));
  proto::TimeSyncResponse ts{};
  REQUIRE(proto::read_payload(rsp, ts) == proto::Error::ok);
  CHECK(ts.host_time_us == 123456789);
  CHECK(ts.device_rx_us <= ts.device_tx_us);
  CHECK(ts.device_rx_us == doctest::Approx(100000.0).epsilon(0.05));

  rsp = ask(b, dev, proto::make_request(proto::Opcode::get_stats, 3));
  proto::DeviceStats st{};
  REQUIRE(proto::read_payload(rsp, st) == proto::Error::ok);
  CHECK(st.reports_sent >= 50);
  CHECK(st.lost_blocks == 0);

  rsp = ask(b, dev, proto::make_request(proto::Opcode::get_config, 4));
  proto::DeviceConfig cfg{};
  REQUIRE(proto::read_payload(rsp, cfg) == proto::Error::ok);
  CHECK(cfg == dev.config());
}

TEST_CASE("bad input: malformed and unknown commands, out-of-range configuration") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  const proto::DeviceConfig before = dev.config();

  SUBCASE("unknown opcode") {
    proto::Request req = proto::make_request(static_cast<proto::Opcode>(0x55), 9);
    const proto::Response rsp = ask(b, dev, req);
    CHECK(rsp.status == proto::Status::unknown_opcode);
    CHECK(static_cast<int>(rsp.opcode) == 0x55);
  }
  SUBCASE("corrupt CRC is answered with bad_crc and the request's token") {
    auto bytes = hid_request(proto::make_request(proto::Opcode::get_config, 17));
    bytes[5] ^= 0xFF;  // the CRC of an empty payload sits at 1 + 4
    b.hid.inbox.push_back(bytes);
    b.step(dev);
    const auto rsp = take_response(b.hid);
    REQUIRE(rsp.has_value());
    CHECK(rsp->status == proto::Status::bad_crc);
    CHECK(rsp->token == 17);
  }
  SUBCASE("another protocol version") {
    auto bytes = hid_request(proto::make_request(proto::Opcode::get_config, 18));
    bytes[1] = 9;
    b.hid.inbox.push_back(bytes);
    b.step(dev);
    const auto rsp = take_response(b.hid);
    REQUIRE(rsp.has_value());
    CHECK(rsp->status == proto::Status::bad_version);
  }
  SUBCASE("garbage, a wrong report id and an empty report get no answer and are counted") {
    b.hid.inbox.push_back({0x02, 0x01});
    b.hid.inbox.push_back({0x01, 1, 2, 3, 4, 5, 6, 7});
    b.hid.inbox.push_back({});
    b.step(dev);
    CHECK_FALSE(take_response(b.hid).has_value());
    CHECK(dev.stats().commands_rejected == 3);
  }
  SUBCASE("short set_config payload") {
    proto::Request req = proto::make_request(proto::Opcode::set_config, 5);
    req.length = 10;
    CHECK(ask(b, dev, req).status == proto::Status::bad_length);
    CHECK(dev.config() == before);
  }
  SUBCASE("out-of-range values are refused with the field, config unchanged") {
    struct Case {
      const char* what;
      void (*edit)(proto::DeviceConfig&);
      proto::ConfigField field;
    };
    const Case cases[] = {
        {"high-pass below 1 Hz", [](proto::DeviceConfig& c) { c.highpass_dhz = 5; }, proto::ConfigField::highpass_dhz},
        {"low-pass at Nyquist", [](proto::DeviceConfig& c) { c.lowpass_dhz = 10000; }, proto::ConfigField::lowpass_dhz},
        {"notch 55 Hz", [](proto::DeviceConfig& c) { c.notch_hz = 55; }, proto::ConfigField::notch_hz},
        {"tau 1 ms", [](proto::DeviceConfig& c) { c.envelope_tau_ms = 1; }, proto::ConfigField::envelope_tau_ms},
        {"group 9", [](proto::DeviceConfig& c) { c.pair_group[1] = 9; }, proto::ConfigField::pair_group},
        {"pair 5 of a 4-pair band", [](proto::DeviceConfig& c) { c.pair_group[5] = 0; },
         proto::ConfigField::pair_group},
        {"report rate 0", [](proto::DeviceConfig& c) { c.report_rate_hz = 0; }, proto::ConfigField::report_rate_hz},
        {"CAN node 40", [](proto::DeviceConfig& c) { c.can_node_id = 40; }, proto::ConfigField::can_node_id},
    };
    for (const Case& c : cases) {
      INFO(c.what);
      proto::DeviceConfig cfg = dev.config();
      c.edit(cfg);
      const proto::Response rsp = ask(b, dev, request(proto::Opcode::set_config, 6, cfg));
      CHECK(rsp.status == proto::Status::bad_value);
      proto::SetConfigResult r{};
      REQUIRE(proto::read_payload(rsp, r) == proto::Error::ok);
      CHECK(r.rejected == c.field);
      CHECK(dev.config() == before);
    }
    // An enum value the decoder refuses is named too.
    proto::Request req = request(proto::Opcode::set_config, 7, dev.config());
    req.payload[10] = 7;  // envelope_mode
    const proto::Response rsp = ask(b, dev, req);
    CHECK(rsp.status == proto::Status::bad_value);
    proto::SetConfigResult r{};
    REQUIRE(proto::read_payload(rsp, r) == proto::Error::ok);
    CHECK(r.rejected == proto::ConfigField::envelope_mode);
    CHECK(dev.config() == before);
    CHECK((dev.status_bits() & proto::status_bit::config_dirty) == 0);
  }
}

TEST_CASE("config set, saved, and loaded after a reboot, factory reset erases it") {
  Bench b(spec(Scenario::rest, 3.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  proto::DeviceConfig cfg = dev.config();
  cfg.notch_hz = 60;
  cfg.report_rate_hz = 500;
  CHECK(ask(b, dev, request(proto::Opcode::set_config, 1, cfg)).status == proto::Status::ok);
  CHECK(dev.config() == cfg);
  CHECK(dev.chain().notch_hz[0] == doctest::Approx(60.0F));
  CHECK((dev.status_bits() & proto::status_bit::config_dirty) != 0);
  CHECK(ask(b, dev, proto::make_request(proto::Opcode::save_config, 2)).status == proto::Status::ok);
  CHECK((dev.status_bits() & proto::status_bit::config_dirty) == 0);

  CHECK(ask(b, dev, request(proto::Opcode::reset, 3, proto::ResetRequest{proto::ResetKind::reboot})).status ==
        proto::Status::ok);
  CHECK(dev.boot_load_result() == LoadResult::loaded);  // the bench rebooted it
  CHECK(dev.config() == cfg);
  const std::uint32_t reports_after_boot = dev.reports();
  CHECK(reports_after_boot <= 1);

  CHECK(ask(b, dev, request(proto::Opcode::reset, 4, proto::ResetRequest{proto::ResetKind::factory_defaults})).status ==
        proto::Status::ok);
  CHECK(dev.boot_load_result() == LoadResult::empty);
  CHECK(dev.config() == default_config(b.gen.front_end()));
}

TEST_CASE("a lost block is counted and flagged once, a repeated block is never processed twice") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.1F);
  const std::uint32_t before = dev.reports();
  b.sequence += 3;  // three blocks overwritten by the DMA
  b.step(dev);
  b.step(dev);  // two 1 ms blocks: one report at 500 Hz
  CHECK(dev.stats().lost_blocks == 3);
  CHECK(dev.reports() == before + 1);
  std::uint16_t flagged = 0;
  dev.set_report_observer(
      [](void* ctx, const proto::StreamMessage& m) {
        if ((m.status & proto::status_bit::block_lost) != 0) ++*static_cast<std::uint16_t*>(ctx);
      },
      &flagged);
  b.run_for(dev, 0.1F);
  CHECK(flagged == 0);  // the flag went out with the first report after the loss only
  CHECK((dev.status_bits() & proto::status_bit::block_lost) == 0);

  // Same sequence again (a driver bug or a re-queued half): dropped.
  const std::uint32_t reports = dev.reports();
  b.sequence -= 1;
  b.step(dev);
  CHECK(dev.reports() == reports);
  CHECK(dev.stale_blocks() == 1);
  CHECK(dev.stats().lost_blocks == 3);
}

TEST_CASE("a block processed long after it was sampled is counted late, and still processed once") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.1F);
  CHECK(dev.stats().late_blocks == 0);
  const std::uint32_t reports = dev.reports();
  // The main loop stalled for 10 ms (e.g. a flash erase): the next block is old news.
  hal::SampleBlock late{};
  late.sequence = b.sequence++;
  late.frames = 4;  // 2 ms: one report at 500 Hz
  late.first_sample_us = b.clock.now_us();
  b.clock.advance_to(late.first_sample_us + 12000);
  b.sampler.push(late);
  dev.poll();
  CHECK(dev.stats().late_blocks == 1);
  CHECK(dev.stats().lost_blocks == 0);
  CHECK(dev.reports() == reports + 1);
}

TEST_CASE("scripted faults raise their flags on their channels, at their times") {
  const float T = 10.0F;
  Bench b(spec(Scenario::faults, T));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  struct Seen {
    std::array<std::array<float, 2>, 3> window{};  // first/last time of off(ch2), sat(ch5), artifact(ch0)
    std::uint16_t off = 0, sat = 0, art = 0;
    int lost = 0;
    float lost_at = -1.0F;
  } seen;
  for (auto& w : seen.window) w = {-1.0F, -1.0F};
  dev.set_report_observer(
      [](void* ctx, const proto::StreamMessage& m) {
        auto& s = *static_cast<Seen*>(ctx);
        const float t = static_cast<float>(m.device_time_us) * 1e-6F;
        const auto mark = [&](std::size_t k, bool on) {
          if (!on) return;
          if (s.window[k][0] < 0) s.window[k][0] = t;
          s.window[k][1] = t;
        };
        mark(0, (m.electrode_off >> FaultScript::kOffChannel) & 1U);
        mark(1, (m.saturation >> FaultScript::kSaturatedChannel) & 1U);
        mark(2, (m.artifact >> FaultScript::kArtifactChannel) & 1U);
        s.off |= m.electrode_off;
        s.sat |= m.saturation;
        s.art |= m.artifact;
        if ((m.status & proto::status_bit::block_lost) != 0) {
          ++s.lost;
          s.lost_at = t;
        }
      },
      &seen);
  while (b.step(dev)) {
  }
  CHECK(seen.off == (1U << FaultScript::kOffChannel));
  CHECK(seen.sat == (1U << FaultScript::kSaturatedChannel));
  CHECK(seen.art == (1U << FaultScript::kArtifactChannel));
  // Each flag inside its scripted window, give or take two 100 ms detector windows.
  const float slack = 0.25F;
  CHECK(seen.window[0][0] >= FaultScript::kOffStart * T);
  CHECK(seen.window[0][0] <= FaultScript::kOffStart * T + slack);
  CHECK(seen.window[0][1] <= FaultScript::kOffEnd * T + slack);
  CHECK(seen.window[1][0] >= FaultScript::kSatStart * T);
  CHECK(seen.window[1][1] <= FaultScript::kSatEnd * T + slack);
  CHECK(seen.window[2][0] >= FaultScript::kArtifactStart * T);
  // The artifact flag also covers the DC tracker's recovery after the swing (~2 x 0.32 s).
  CHECK(seen.window[2][1] <= FaultScript::kArtifactEnd * T + 0.7F);
  CHECK(seen.lost == 1);
  CHECK(seen.lost_at == doctest::Approx(FaultScript::kLostBlockAt * T).epsilon(0.01));
  CHECK(dev.stats().lost_blocks == 1);
}

TEST_CASE("clean synthetic scenarios raise no flags, a broken lead reads as electrode off") {
  for (Scenario s : {Scenario::rest, Scenario::ramp, Scenario::bursts, Scenario::hum}) {
    INFO(to_string(s));
    Bench b(spec(s, 4.0F));
    hal::Board board = b.board();
    Device dev(board);
    dev.boot();
    std::uint16_t any = 0;
    dev.set_report_observer(
        [](void* ctx, const proto::StreamMessage& m) {
          *static_cast<std::uint16_t*>(ctx) |= m.electrode_off | m.saturation | m.artifact;
        },
        &any);
    while (b.step(dev)) {
    }
    CHECK(any == 0);
  }
  Bench b(spec(Scenario::dropout, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  while (b.step(dev)) {
  }
  CHECK(dev.last_report().electrode_off == (1U << 3));
  CHECK(dev.last_report().levels[1] == 0);  // its pair relaxes rather than reading garbage
}

TEST_CASE("calibration over commands, the host disappearing mid-phase leaves a consistent device") {
  SynthSpec sp = spec(Scenario::ramp, 20.0F);
  Bench b(sp);
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  // Ramp: rest for the first 10 % (2 s). Calibrate rest during 0.5..1.5 s.
  b.run_for(dev, 0.5F);
  proto::CalibrationStart rest{};
  rest.duration_ms = 1000;
  proto::Response rsp = ask(b, dev, request(proto::Opcode::calibration_start, 1, rest));
  CHECK(rsp.status == proto::Status::ok);
  CHECK((dev.status_bits() & proto::status_bit::calibrating) != 0);
  CHECK(ask(b, dev, request(proto::Opcode::calibration_start, 2, rest)).status == proto::Status::wrong_state);
  CHECK(ask(b, dev, proto::make_request(proto::Opcode::save_config, 3)).status == proto::Status::wrong_state);
  // The host now goes away: no more commands. The phase ends on sample time.
  b.run_for(dev, 1.2F);
  proto::CalibrationStatus st = dev.calibrator().status(dev.calibration());
  CHECK(st.state == proto::CalibrationState::done);
  CHECK(dev.calibration().baseline_mask == 0xFF);
  CHECK((dev.status_bits() & proto::status_bit::config_dirty) != 0);  // in RAM only
  {
    Persisted p{};  // the storage holds only the boot's record (its boot count), uncalibrated
    REQUIRE(load_persisted(b.storage, p) == LoadResult::loaded);
    CHECK(p.calibration.baseline_mask == 0);
    CHECK(p.boot_count == 1);
  }
  // A host comes back, runs the MVC at the top of the ramp, and saves.
  b.run_for(dev, 16.0F);
  proto::CalibrationStart mvc{};
  mvc.phase = proto::CalibrationPhase::max_contraction;
  mvc.duration_ms = 1500;
  CHECK(ask(b, dev, request(proto::Opcode::calibration_start, 4, mvc)).status == proto::Status::ok);
  b.run_for(dev, 1.6F);
  rsp = ask(b, dev, proto::make_request(proto::Opcode::calibration_status, 5));
  REQUIRE(proto::read_payload(rsp, st) == proto::Error::ok);
  CHECK(st.state == proto::CalibrationState::done);
  CHECK(st.calibrated_mask == 0xFF);
  CHECK(st.phases_done == 0b011);
  CHECK((dev.status_bits() & proto::status_bit::calibrated) != 0);
  CHECK(ask(b, dev, proto::make_request(proto::Opcode::save_config, 6)).status == proto::Status::ok);
  // Calibrated envelopes: near 1.0 (32768) at the top of the ramp.
  CHECK(dev.last_report().envelopes[0] > 20000);
  // Abort with nothing running is refused.
  CHECK(ask(b, dev, proto::make_request(proto::Opcode::calibration_abort, 7)).status == proto::Status::wrong_state);
  // The saved calibration survives a reboot.
  dev.boot();
  CHECK(dev.boot_load_result() == LoadResult::loaded);
  CHECK(dev.calibration().calibrated_mask() == 0xFF);
}

TEST_CASE("a co-contraction ramp through the whole device: levels rise with it, hysteresis stops the chatter") {
  // The envelope of random EMG has an estimation noise of ~10 % at tau = 100 ms
  // (De Luca 1997), so report-to-report the level moves both ways; what must
  // hold is that it follows the ramp (rising 1 s means) and that the hysteresis
  // holds it still through most of that noise.
  struct Track {
    std::array<std::uint16_t, kGroups> last{};
    std::array<int, kGroups> changes{};
    std::vector<std::array<double, kGroups>> second_means;
    std::array<double, kGroups> acc{};
    int n = 0;
    int per_second = 0;  // reports
  };
  const auto run = [](std::uint16_t hysteresis, Track& track) {
    Bench b(spec(Scenario::ramp, 10.0F));
    hal::Board board = b.board();
    Device dev(board);
    dev.boot();
    proto::DeviceConfig cfg = dev.config();
    cfg.hysteresis = hysteresis;
    proto::Response rsp = ask(b, dev, request(proto::Opcode::set_config, 1, cfg));
    REQUIRE(rsp.status == proto::Status::ok);
    track.per_second = cfg.report_rate_hz;
    dev.set_report_observer(
        [](void* ctx, const proto::StreamMessage& m) {
          auto& t = *static_cast<Track*>(ctx);
          for (std::size_t g = 0; g < kGroups; ++g) {
            if (m.levels[g] != t.last[g]) ++t.changes[g];
            t.last[g] = m.levels[g];
            t.acc[g] += m.levels[g];
          }
          if (++t.n == t.per_second) {
            for (double& a : t.acc) a /= t.per_second;
            t.second_means.push_back(t.acc);
            t.acc = {};
            t.n = 0;
          }
        },
        &track);
    while (b.step(dev)) {
    }
  };
  Track with, without;
  run(proto::DeviceConfig{}.hysteresis, with);
  run(0, without);
  REQUIRE(with.second_means.size() >= 9);
  for (std::size_t g = 0; g < kGroups; ++g) {
    INFO("group " << g);
    // Rest for the first second, then rising every second until full scale.
    CHECK(with.second_means[0][g] < 0.02 * 65535);
    for (std::size_t s = 2; s < with.second_means.size(); ++s) {
      CHECK(with.second_means[s][g] >= std::min(with.second_means[s - 1][g] + 500.0, 0.99 * 65535));
    }
    CHECK(with.last[g] > 0.8 * 65535);
    MESSAGE("group " << g << ": level changes in 10 s of reports: " << with.changes[g] << " with hysteresis, "
                     << without.changes[g] << " without");
    CHECK(with.changes[g] * 4 < without.changes[g]);
  }
}

TEST_CASE("a co-contraction swell through the whole device: levels rise to the top and fall back") {
  // tonusd --demo's pattern: 0.5 * peak * (1 - cos(2 pi t / P)), P = 4 s here.
  SynthSpec sp = spec(Scenario::swell, 4.0F);
  sp.swell_period_s = 4.0F;
  Bench b(sp);
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  struct Means {
    std::array<double, 8> sum{};  // group 0, per half second
    std::array<int, 8> n{};
    std::uint32_t t0 = 0;
    bool started = false;
  } means;
  dev.set_report_observer(
      [](void* ctx, const proto::StreamMessage& m) {
        auto& mm = *static_cast<Means*>(ctx);
        if (!mm.started) {
          mm.t0 = m.device_time_us;
          mm.started = true;
        }
        const auto slot = static_cast<std::size_t>((m.device_time_us - mm.t0) / 500000U);
        if (slot < mm.sum.size()) {
          mm.sum[slot] += m.levels[0];
          ++mm.n[slot];
        }
      },
      &means);
  while (b.step(dev)) {
  }
  std::array<double, 8> mean{};
  for (std::size_t k = 0; k < mean.size(); ++k) {
    REQUIRE(means.n[k] > 0);
    mean[k] = means.sum[k] / means.n[k];
  }
  MESSAGE("group 0 level, half-second means: " << mean[0] << " " << mean[1] << " " << mean[2] << " " << mean[3] << " "
                                               << mean[4] << " " << mean[5] << " " << mean[6] << " " << mean[7]);
  CHECK(mean[0] < 0.1 * 65535);
  CHECK(std::max(mean[3], mean[4]) > 0.5 * 65535);
  CHECK(mean[1] < mean[3]);
  CHECK(mean[6] < mean[4]);
  CHECK(mean[7] < 0.25 * 65535);
}

TEST_CASE("CAN: segmented request and response, stream cycles and heartbeat") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.05F);
  std::array<std::uint8_t, proto::kMaxMessageSize> bytes{};
  std::size_t n = 0;
  proto::Request req{};
  req = proto::make_request(proto::Opcode::get_config, 33);
  REQUIRE(proto::encode_request(req, bytes, n) == proto::Error::ok);
  std::array<proto::CanFrame, proto::can::kMaxSegments> frames{};
  std::size_t count = 0;
  REQUIRE(proto::can::segment(std::span<const std::uint8_t>(bytes).first(n), proto::can::Function::request, 1, frames,
                              count) == proto::Error::ok);
  for (std::size_t k = 0; k < count; ++k) b.can.inbox.push_back(frames[k]);
  b.can.sent.clear();
  b.step(dev);
  b.step(dev);  // two 1 ms blocks: one stream cycle at 500 Hz
  proto::can::Reassembler reasm(proto::can::Function::response, 1);
  proto::can::StreamAssembler stream(1);
  bool got_response = false;
  int cycles = 0;
  for (const proto::CanFrame& f : b.can.sent) {
    bool complete = false;
    REQUIRE(reasm.push(f, complete) == proto::Error::ok);
    if (complete) {
      proto::Response rsp{};
      REQUIRE(proto::decode_response(reasm.message(), rsp) == proto::Error::ok);
      CHECK(rsp.token == 33);
      proto::DeviceConfig cfg{};
      REQUIRE(proto::read_payload(rsp, cfg) == proto::Error::ok);
      CHECK(cfg == dev.config());
      got_response = true;
    }
    REQUIRE(stream.push(f, complete) == proto::Error::ok);
    if (complete) ++cycles;
  }
  CHECK(got_response);
  CHECK(cycles == 1);
  // A heartbeat went out at boot, the next one a second later.
  b.can.sent.clear();
  b.run_for(dev, 1.0F);
  int heartbeats = 0;
  for (const proto::CanFrame& f : b.can.sent) {
    proto::can::Heartbeat hb{};
    if (proto::can::decode_heartbeat(f, hb) == proto::Error::ok) {
      ++heartbeats;
      CHECK(hb.state == proto::can::NodeState::running);
    }
  }
  CHECK(heartbeats == 1);
}

TEST_CASE("CAN: a set_config that changes the node id is answered from the old id, then the new one serves") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.05F);
  const std::uint8_t old_id = dev.config().can_node_id;
  const std::uint8_t new_id = static_cast<std::uint8_t>(old_id == 7 ? 8 : 7);  // ids run 0..31
  proto::DeviceConfig cfg = dev.config();
  cfg.can_node_id = new_id;
  const auto answer = ask_can(b, dev, request(proto::Opcode::set_config, 9, cfg), old_id, old_id);
  REQUIRE(answer.has_value());  // before the fix it came from the new id: the host waiting on the old one timed out
  CHECK(answer->token == 9);
  CHECK(answer->status == proto::Status::ok);
  CHECK(dev.config().can_node_id == new_id);
  // From now on the device listens and answers on the new id only.
  const auto next = ask_can(b, dev, proto::make_request(proto::Opcode::get_config, 10), new_id, new_id);
  REQUIRE(next.has_value());
  CHECK(next->token == 10);
  CHECK_FALSE(ask_can(b, dev, proto::make_request(proto::Opcode::get_config, 11), old_id, old_id).has_value());
}

TEST_CASE("CAN id base: a band moved off the CANopen ids answers on the old plan, then streams on 29-bit ids") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.05F);
  constexpr std::uint32_t kBase = 0x1A000000;
  const std::uint8_t node = dev.config().can_node_id;
  proto::DeviceConfig cfg = dev.config();
  cfg.can_id_base = kBase + 1;  // not a multiple of 0x800: refused, nothing changes
  const auto refused = ask_can(b, dev, request(proto::Opcode::set_config, 1, cfg), node, node, 0);
  REQUIRE(refused.has_value());
  CHECK(refused->status == proto::Status::bad_value);
  cfg.can_id_base = kBase;
  const auto answer = ask_can(b, dev, request(proto::Opcode::set_config, 2, cfg), node, node, 0);
  REQUIRE(answer.has_value());  // answered on the 11-bit plan the request came on
  CHECK(answer->status == proto::Status::ok);
  // Now every frame is extended at the base: none may use an 11-bit (CANopen) id.
  b.can.sent.clear();
  b.run_for(dev, 1.1F);
  int cycles = 0, heartbeats = 0;
  proto::can::StreamAssembler stream(node, kBase);
  for (const proto::CanFrame& f : b.can.sent) {
    CHECK((f.flags & proto::CanFrame::kExtended) != 0);
    CHECK((f.id & ~std::uint32_t{0x7FF}) == kBase);
    bool complete = false;
    REQUIRE(stream.push(f, complete) == proto::Error::ok);
    if (complete) ++cycles;
    proto::can::Heartbeat hb{};
    if (proto::can::decode_heartbeat(f, hb, kBase) == proto::Error::ok) ++heartbeats;
  }
  CHECK(cycles >= 540);
  CHECK(heartbeats == 1);
  const auto next = ask_can(b, dev, proto::make_request(proto::Opcode::get_config, 3), node, node, kBase);
  REQUIRE(next.has_value());
  proto::DeviceConfig back{};
  REQUIRE(proto::read_payload(*next, back) == proto::Error::ok);
  CHECK(back.can_id_base == kBase);
  CHECK_FALSE(ask_can(b, dev, proto::make_request(proto::Opcode::get_config, 4), node, node, 0)
                  .has_value());  // the old plan is gone
}

TEST_CASE("a stalled sampler is restarted once, then reported as a fault and the watchdog left to reset the chip") {
  Bench b(spec(Scenario::rest, 8.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.5F);
  const int starts = b.sampler.starts();
  // The main loop keeps running, but no block arrives (DMA stuck).
  const auto heartbeat_state = [&] {
    std::optional<proto::can::NodeState> state;
    for (const proto::CanFrame& f : b.can.sent) {
      proto::can::Heartbeat hb{};
      if (proto::can::decode_heartbeat(f, hb) == proto::Error::ok) state = hb.state;
    }
    b.can.sent.clear();
    return state;
  };
  const auto idle = [&](double seconds) {
    const std::uint64_t until = b.clock.now_us() + static_cast<std::uint64_t>(seconds * 1e6);
    while (b.clock.now_us() < until) {
      b.clock.advance_to(b.clock.now_us() + 10000);
      dev.poll();
    }
  };
  b.can.sent.clear();
  idle(0.25);
  CHECK(b.sampler.starts() == starts + 1);  // restarted once
  CHECK_FALSE(dev.sampler_stalled());
  const std::uint64_t kicks_before = b.watchdog.kicks();
  idle(1.5);
  CHECK(dev.sampler_stalled());
  CHECK(b.sampler.starts() == starts + 1);                   // no restart storm
  CHECK(heartbeat_state() == proto::can::NodeState::fault);  // was "running" before the fix
  CHECK(b.led.pattern() == hal::LedPattern::fault);
  CHECK(b.watchdog.kicks() < kicks_before + 25);  // kicks stopped once stalled (within 0.2 s)
  const std::uint64_t kicks_stalled = b.watchdog.kicks();
  idle(0.5);
  CHECK(b.watchdog.kicks() == kicks_stalled);
  // Blocks come back (the sampler recovered): running again, kicks resume. (The
  // synthetic blocks' times are behind the idle clock, so give it time to pass.)
  b.run_for(dev, 4.0F);
  CHECK_FALSE(dev.sampler_stalled());
  CHECK(heartbeat_state() == proto::can::NodeState::running);
  CHECK(b.watchdog.kicks() > kicks_stalled);
}

TEST_CASE("device info (minor 1): protocol minor, features, boot count across reboots, reset cause") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  std::uint32_t last_boot = 0;
  for (int k = 0; k < 3; ++k) {
    if (k == 0) {
      dev.boot();
    } else {
      REQUIRE(ask(b, dev, request(proto::Opcode::reset, 9, proto::ResetRequest{})).status == proto::Status::ok);
      for (int f = 0; f < 60 && b.reboots < k; ++f) b.step(dev);
      REQUIRE(b.reboots == k);
    }
    proto::DeviceInfo info{};
    REQUIRE(proto::read_payload(ask(b, dev, proto::make_request(proto::Opcode::get_device_info, 1)), info) ==
            proto::Error::ok);
    CHECK(info.protocol_minor == proto::kProtocolMinor);
    CHECK((info.features & proto::feature_bit::fault_log) != 0);
    CHECK((info.features & proto::feature_bit::bootloader) != 0);  // the simulator has one
    CHECK(info.boot_count == last_boot + 1);                       // persisted with the configuration
    last_boot = info.boot_count;
    CHECK(info.reset_cause == (k == 0 ? proto::ResetCause::power_on : proto::ResetCause::software));
  }
  // A factory reset erases the count with the rest.
  REQUIRE(
      ask(b, dev, request(proto::Opcode::reset, 9, proto::ResetRequest{proto::ResetKind::factory_defaults})).status ==
      proto::Status::ok);
  for (int f = 0; f < 60 && b.reboots < 3; ++f) b.step(dev);
  CHECK(dev.boot_count() == 1);
}

TEST_CASE("fault log: a stalled sampler is logged, read once, repeats merged, overflow counted") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.05F);
  // The sampler stops delivering: a restart, then the stall.
  for (int k = 0; k < 50; ++k) {
    b.clock.advance_to(b.clock.now_us() + 10000);
    dev.poll();
  }
  REQUIRE(dev.sampler_stalled());
  proto::FaultLog log{};
  REQUIRE(proto::read_payload(ask(b, dev, proto::make_request(proto::Opcode::get_log, 1)), log) == proto::Error::ok);
  REQUIRE(log.count == 2);
  CHECK(log.entries[0].code == proto::FaultCode::sampler_restarted);
  CHECK(log.entries[1].code == proto::FaultCode::sampler_stalled);
  CHECK(log.entries[1].time_ms > log.entries[0].time_ms);
  CHECK(log.entries[1].time_ms - log.entries[0].time_ms >= kSamplerStallUs / 1000U);
  CHECK(log.more == 0);
  REQUIRE(proto::read_payload(ask(b, dev, proto::make_request(proto::Opcode::get_log, 2)), log) == proto::Error::ok);
  CHECK(log.count == 0);  // read means removed

  // The ring itself: merges, keeps the newest, counts what it dropped.
  fw::FaultLog ring;
  for (int k = 0; k < 300; ++k) ring.record(proto::FaultCode::blocks_lost, static_cast<std::uint16_t>(k), 5);
  CHECK(ring.size() == 1);
  for (std::uint32_t k = 0; k < 40; ++k) {
    ring.record(k % 2 == 0 ? proto::FaultCode::can_down : proto::FaultCode::storage_error, 0, 10 + k);
  }
  CHECK(ring.size() == fw::kFaultLogCapacity);
  CHECK(ring.dropped() == 41 - fw::kFaultLogCapacity);
  proto::FaultLog out{};
  ring.take(out);
  CHECK(out.count == proto::FaultLog::kMaxEntries);
  CHECK(out.more == 1);
  CHECK(out.dropped == 41 - fw::kFaultLogCapacity);
  CHECK(out.entries[0].time_ms == 10 + 40 - fw::kFaultLogCapacity);  // the oldest kept
}

TEST_CASE("enter_bootloader: answered first, then the board's bootloader, refused where there is none") {
  Bench b(spec(Scenario::rest, 2.0F));
  hal::Board board = b.board();
  Device dev(board);
  dev.boot();
  b.run_for(dev, 0.02F);
  const proto::Response rsp = ask(b, dev, proto::make_request(proto::Opcode::enter_bootloader, 4));
  CHECK(rsp.status == proto::Status::ok);
  for (int f = 0; f < 60 && b.reboots == 0; ++f) b.step(dev);
  CHECK(b.system.bootloader_entries() == 1);
  CHECK(b.reboots == 1);

  // A board without an update bootloader says so.
  struct NoBootloader final : hal::SystemControl {
    void reset() override {}
  } plain;
  hal::Board other{b.sampler, b.clock, b.storage, b.led, b.watchdog, plain, &b.hid, &b.can, 42, 1};
  Device dev2(other);
  dev2.boot();
  proto::Response r2{};
  dev2.handle(proto::make_request(proto::Opcode::enter_bootloader, 5), 0, r2);
  CHECK(r2.status == proto::Status::wrong_state);
}
