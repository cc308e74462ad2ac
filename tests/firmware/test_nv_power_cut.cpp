// The record log under power cuts: a cut at every byte of every save (and at
// every step of every sector erase) must leave a valid record, the one saved
// last or the one before it, and the next save must succeed.
#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <vector>

#include "tonus/firmware/nv_record.hpp"
#include "tonus/protocol/crc16.hpp"
#include "tonus/protocol/wire.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

// Flash whose power can be cut after a given number of byte operations (a
// programmed byte, or one byte of an erase). At the cut the byte in progress
// is left half-done, and nothing after it happens.
class CutFlash final : public hal::Storage {
 public:
  static constexpr std::size_t kSector = 4 * kRecordSlot;  // small sectors: many switches
  CutFlash() : bytes_(2 * kSector, 0xFF) {}
  [[nodiscard]] std::size_t sector_size() const override { return kSector; }
  [[nodiscard]] std::size_t sector_count() const override { return 2; }
  bool read(std::size_t offset, std::span<std::uint8_t> out) override {
    if (offset > bytes_.size() || out.size() > bytes_.size() - offset) return false;
    std::copy_n(bytes_.begin() + static_cast<std::ptrdiff_t>(offset), out.size(), out.begin());
    return true;
  }
  bool erase(std::size_t sector) override {
    if (sector >= 2) return false;
    for (std::size_t k = 0; k < kSector; ++k) {
      std::uint8_t& b = bytes_[sector * kSector + k];
      if (!tick()) {
        b = static_cast<std::uint8_t>(b | 0x0F);  // half erased
        return false;
      }
      b = 0xFF;
    }
    return true;
  }
  bool program(std::size_t offset, std::span<const std::uint8_t> data) override {
    if (offset > bytes_.size() || data.size() > bytes_.size() - offset) return false;
    for (std::size_t k = 0; k < data.size(); ++k) {
      std::uint8_t& b = bytes_[offset + k];
      if (!tick()) {
        b = static_cast<std::uint8_t>(b & (data[k] | 0xF0));  // half programmed
        return false;
      }
      b = static_cast<std::uint8_t>(b & data[k]);
    }
    return true;
  }
  void cut_after(std::size_t ops) {
    cut_ = true;
    left_ = ops;
  }
  void power_on() { cut_ = false; }
  [[nodiscard]] std::size_t ops() const { return ops_; }
  std::vector<std::uint8_t> bytes_;

 private:
  bool tick() {
    ++ops_;
    if (!cut_) return true;
    if (left_ == 0) return false;
    --left_;
    return true;
  }
  bool cut_ = false;
  std::size_t left_ = 0;
  std::size_t ops_ = 0;
};

Persisted version(int k) {
  Persisted p{};
  p.calibration = default_calibration(FrontEnd{});
  p.calibration.baseline[1] = 1.0F + static_cast<float>(k);
  p.config.envelope_tau_ms = static_cast<std::uint16_t>(20 + k);
  return p;
}

}  // namespace

TEST_CASE("a power cut at every byte of every save leaves the last or the previous record, never none") {
  CutFlash flash;
  constexpr int kSaves = 20;  // 4 slots per sector: the log changes sector every 4 saves
  std::size_t cuts = 0;
  for (int i = 1; i <= kSaves; ++i) {
    const std::vector<std::uint8_t> before = flash.bytes_;
    // How many byte operations this save takes with the power on.
    const std::size_t ops0 = flash.ops();
    REQUIRE(save_persisted(flash, version(i)));
    const std::size_t ops = flash.ops() - ops0;
    const std::vector<std::uint8_t> after = flash.bytes_;
    for (std::size_t c = 0; c < ops; ++c) {
      flash.bytes_ = before;
      flash.cut_after(c);
      (void)save_persisted(flash, version(i));
      flash.power_on();
      Persisted out{};
      const LoadResult r = load_persisted(flash, out);
      if (i == 1) {
        CHECK((r == LoadResult::empty || r == LoadResult::corrupt || (r == LoadResult::loaded && out == version(1))));
      } else {
        REQUIRE(r == LoadResult::loaded);
        REQUIRE((out == version(i - 1) || out == version(i)));
      }
      // Power back: the save is repeated and lands.
      REQUIRE(save_persisted(flash, version(i)));
      REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
      REQUIRE(out == version(i));
      ++cuts;
    }
    flash.bytes_ = after;
  }
  MESSAGE(cuts << " power cuts over " << kSaves << " saves");
  CHECK(cuts > static_cast<std::size_t>(kSaves) * kRecordSlot);
}

TEST_CASE("a version 1 log (one sector, 128-byte slots) is read, then superseded in the other sector") {
  CutFlash flash;
  // A version-1 record written field by field as firmware 0.5 did: magic,
  // version 1, length, the minor-0 DeviceConfig (31 bytes), the calibration,
  // the masks, CRC; no generation, no boot count.
  const Persisted old = version(7);
  std::array<std::uint8_t, kRecordSlot1> v1{};
  v1.fill(0xFF);
  std::array<std::uint8_t, proto::DeviceConfig::kWireSize> config{};
  proto::ByteWriter cw(config);
  old.config.write(cw);
  proto::ByteWriter w(v1);
  w.u32(kRecordMagic);
  w.u8(kRecordVersion1);
  w.u8(0);
  w.bytes(std::span<const std::uint8_t>(config).first(proto::DeviceConfig::kMinWireSize));
  for (float f : old.calibration.baseline) w.u32(std::bit_cast<std::uint32_t>(f));
  for (float f : old.calibration.reference) w.u32(std::bit_cast<std::uint32_t>(f));
  for (float f : old.calibration.cocontraction) w.u32(std::bit_cast<std::uint32_t>(f));
  w.u16(old.calibration.baseline_mask);
  w.u16(old.calibration.reference_mask);
  w.u8(old.calibration.cocontraction_mask);
  const std::size_t body = w.size() - 6;
  v1[5] = static_cast<std::uint8_t>(body);
  w.u16(proto::crc16_ccitt(std::span<const std::uint8_t>(v1).first(6 + body)));
  REQUIRE(w.ok());
  REQUIRE(flash.program(0, v1));
  Persisted out{};
  REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
  Persisted expected = version(7);
  expected.boot_count = 0;  // version 1 had none
  CHECK(out == expected);
  REQUIRE(save_persisted(flash, version(8)));
  REQUIRE(load_persisted(flash, out) == LoadResult::loaded);
  CHECK(out == version(8));
  CHECK(std::equal(v1.begin(), v1.end(), flash.bytes_.begin()));  // the old copy was not erased first
}
