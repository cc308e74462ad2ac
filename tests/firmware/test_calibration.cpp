// Calibration state machine (phases, abort, timeout) and the persisted
// record (round trip, corrupt, old version, torn newest record).
#include <doctest/doctest.h>

#include <limits>

#include "sim_hal.hpp"
#include "tonus/firmware/calibration.hpp"
#include "tonus/firmware/nv_record.hpp"
#include "tonus/protocol/crc16.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

proto::CalibrationStart phase(proto::CalibrationPhase p, std::uint16_t ms = 1000, std::uint16_t mask = 0xFF) {
  proto::CalibrationStart s;
  s.phase = p;
  s.duration_ms = ms;
  s.channel_mask = mask;
  return s;
}

void feed(Calibrator& c, Calibration& live, float env, int frames, std::uint16_t off = 0, float cc = 0.0F) {
  std::array<float, kChannels> e{};
  e.fill(env);
  std::array<float, kPairs> pairs{};
  pairs.fill(cc);
  for (int k = 0; k < frames; ++k) c.on_frame(e, off, pairs, live);
}

}  // namespace

TEST_CASE("rest then MVC calibrates every channel") {
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  CHECK(live.calibrated_mask() == 0);
  REQUIRE(cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0) == proto::Status::ok);
  CHECK(cal.running());
  CHECK(cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0) == proto::Status::wrong_state);
  feed(cal, live, 10.0F, 500);
  CHECK(cal.status(live).progress_pct == 50);
  feed(cal, live, 10.0F, 500);
  CHECK(cal.status(live).state == proto::CalibrationState::done);
  CHECK(live.baseline[3] == doctest::Approx(10.0F));
  CHECK(cal.take_changed());
  REQUIRE(cal.start(phase(proto::CalibrationPhase::max_contraction), 1000.0F, 0) == proto::Status::ok);
  feed(cal, live, 150.0F, 999);
  feed(cal, live, 400.0F, 1);  // the peak counts
  CHECK(cal.status(live).state == proto::CalibrationState::done);
  CHECK(live.calibrated_mask() == 0xFF);
  CHECK(live.reference[0] == doctest::Approx(400.0F));
  CHECK(cal.status(live).phases_done == 0b011);
  CHECK(normalise(live, 0, 205.0F) == doctest::Approx(0.5F));
  CHECK(normalise(live, 0, 0.0F) == 0.0F);
}

TEST_CASE("an MVC weaker than twice the rest level does not calibrate, a failed phase keeps the old values") {
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0);
  feed(cal, live, 50.0F, 1000);
  const Calibration before = live;
  cal.start(phase(proto::CalibrationPhase::max_contraction), 1000.0F, 0);
  feed(cal, live, 60.0F, 1000);
  CHECK(cal.status(live).state == proto::CalibrationState::failed);
  CHECK(live == before);
  CHECK(live.calibrated_mask() == 0);
}

TEST_CASE("electrode-off samples are excluded, a channel off the whole phase is left out") {
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0);
  feed(cal, live, 10.0F, 1000, 0b100);
  CHECK(cal.status(live).state == proto::CalibrationState::done);
  CHECK((live.baseline_mask & 0b100) == 0);
  CHECK((live.baseline_mask & 0b011) == 0b011);
}

TEST_CASE("abort and timeout keep the previous calibration") {
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  const Calibration before = live;
  CHECK(cal.abort() == proto::Status::wrong_state);
  cal.start(phase(proto::CalibrationPhase::rest, 2000), 1000.0F, 0);
  feed(cal, live, 10.0F, 1500);
  CHECK(cal.abort() == proto::Status::ok);
  CHECK(cal.status(live).state == proto::CalibrationState::aborted);
  feed(cal, live, 10.0F, 1000);  // samples after the abort change nothing
  CHECK(live == before);

  // Samples stop arriving (sampler stalled): the clock deadline fires.
  cal.start(phase(proto::CalibrationPhase::rest, 2000), 1000.0F, 1'000'000);
  feed(cal, live, 10.0F, 100);
  cal.on_tick(1'000'000 + 2'000'000);  // duration elapsed, still within the grace
  CHECK(cal.running());
  cal.on_tick(1'000'000 + 2'000'000 + kCalibrationGraceMs * 1000 + 1);
  CHECK(cal.status(live).state == proto::CalibrationState::timed_out);
  CHECK(live == before);
  CHECK(cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0) == proto::Status::ok);  // can start again
}

TEST_CASE("bad phase requests are refused") {
  Calibrator cal;
  CHECK(cal.start(phase(proto::CalibrationPhase::rest, 1000, 0xFF00), 1000.0F, 0) == proto::Status::bad_value);
  CHECK(cal.start(phase(proto::CalibrationPhase::co_contraction, 1000, 0b0101), 1000.0F, 0) ==
        proto::Status::bad_value);  // no whole pair
  CHECK(cal.start(phase(proto::CalibrationPhase::rest, 50), 1000.0F, 0) == proto::Status::bad_value);
  CHECK_FALSE(cal.running());
}

TEST_CASE("co-contraction reference per pair") {
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  cal.start(phase(proto::CalibrationPhase::co_contraction, 1000, 0b0011), 1000.0F, 0);
  feed(cal, live, 100.0F, 1000, 0, 0.6F);
  CHECK(cal.status(live).state == proto::CalibrationState::done);
  CHECK(live.cocontraction_mask == 0b0001);
  CHECK(live.cocontraction[0] == doctest::Approx(0.6F));
  CHECK(live.cocontraction[1] == doctest::Approx(1.0F));
}

TEST_CASE("persisted record: round trip, corruption, old version, torn newest record") {
  sim::FlashStorage flash;
  Persisted out{};
  CHECK(load_persisted(flash, out) == LoadResult::empty);

  Persisted a{};
  a.calibration = default_calibration(FrontEnd{});
  a.calibration.baseline[2] = 12.5F;
  a.calibration.baseline_mask = 0x0F;
  a.config.envelope_tau_ms = 80;
  REQUIRE(save_persisted(flash, a));
  REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
  CHECK(out == a);

  Persisted b = a;
  b.config.notch_hz = 60;
  REQUIRE(save_persisted(flash, b));
  REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
  CHECK(out == b);  // the newest wins

  SUBCASE("a torn newest record falls back to the one before") {
    flash.bytes()[kRecordSlot + 20] ^= 0x5A;
    REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
    CHECK(out == a);
  }
  SUBCASE("every record corrupt: defaults") {
    flash.bytes()[10] ^= 0x01;
    flash.bytes()[kRecordSlot + 10] ^= 0x01;
    Persisted untouched{};
    CHECK(load_persisted(flash, untouched) == LoadResult::corrupt);
    CHECK(untouched == Persisted{});
  }
  SUBCASE("a record of another version is not read") {
    sim::FlashStorage old;
    std::array<std::uint8_t, kRecordSlot> slot{};
    const std::size_t n = encode_record(a, 1, slot);
    slot[4] = kRecordVersion + 1;  // a newer firmware's record, with a valid CRC
    const std::uint16_t crc = proto::crc16_ccitt(std::span<const std::uint8_t>(slot).first(n - 2));
    slot[n - 2] = static_cast<std::uint8_t>(crc & 0xFFU);
    slot[n - 1] = static_cast<std::uint8_t>(crc >> 8U);
    old.program(0, slot);
    CHECK(load_persisted(old, out) == LoadResult::old_version);
  }
  SUBCASE("full sectors: the log moves to the other sector and back, newest always wins") {
    for (std::size_t k = 0; k < 3 * sim::FlashStorage::kSize / kRecordSlot + 3; ++k) {
      Persisted p = b;
      p.config.envelope_tau_ms = static_cast<std::uint16_t>(20 + k % 200);
      REQUIRE(save_persisted(flash, p));
      REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
      REQUIRE(out == p);
    }
  }
}

TEST_CASE("a baseline above the reference never sends the levels to full scale") {
  // A stored or measured calibration whose reference is not above its baseline
  // used to divide by 1e-6: any effort read as full scale.
  Calibration c = default_calibration(FrontEnd{});
  c.baseline[0] = 300.0F;
  c.reference[0] = 200.0F;
  CHECK(normalise(c, 0, 310.0F) == 0.0F);
  c.reference[0] = 300.5F;  // under a count of span
  CHECK(normalise(c, 0, 310.0F) == 0.0F);
  c.reference[0] = std::numeric_limits<float>::quiet_NaN();  // a corrupt record
  CHECK(normalise(c, 0, 310.0F) == 0.0F);

  // A rest phase that finds the performer's rest above the old MVC: the MVC is
  // invalidated and the reference raised to the least an MVC could be.
  Calibrator cal;
  Calibration live = default_calibration(FrontEnd{});
  cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0);
  feed(cal, live, 10.0F, 1000);
  cal.start(phase(proto::CalibrationPhase::max_contraction), 1000.0F, 0);
  feed(cal, live, 100.0F, 1000);
  REQUIRE(live.calibrated_mask() == 0xFF);
  cal.start(phase(proto::CalibrationPhase::rest), 1000.0F, 0);
  feed(cal, live, 120.0F, 1000);  // noisier electrodes: rest above the old MVC
  CHECK(cal.status(live).state == proto::CalibrationState::done);
  CHECK(live.calibrated_mask() == 0);
  CHECK(live.reference[0] >= kMvcOverRest * live.baseline[0]);
  CHECK(normalise(live, 0, 126.0F) == doctest::Approx(0.05F).epsilon(0.02));  // 5 % above rest: small
  CHECK(normalise(live, 0, 120.0F) == 0.0F);
}
