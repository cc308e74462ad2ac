#include "tonus/firmware/nv_record.hpp"

#include <array>
#include <bit>

#include "tonus/protocol/crc16.hpp"
#include "tonus/protocol/wire.hpp"

namespace tonus::fw {

namespace {

constexpr std::size_t kHeader = 6;  // magic + version + length

void put_floats(proto::ByteWriter& w, std::span<const float> v) {
  for (float f : v) w.u32(std::bit_cast<std::uint32_t>(f));
}
bool get_floats(proto::ByteReader& r, std::span<float> v) {
  for (float& f : v) {
    f = std::bit_cast<float>(r.u32());
    if (!(f == f)) return false;  // NaN never comes from a real calibration
  }
  return true;
}

bool erased(std::span<const std::uint8_t> bytes) {
  for (std::uint8_t b : bytes) {
    if (b != 0xFF) return false;
  }
  return true;
}

}  // namespace

const char* to_string(LoadResult r) {
  switch (r) {
    case LoadResult::loaded: return "loaded";
    case LoadResult::empty: return "empty";
    case LoadResult::corrupt: return "corrupt";
    case LoadResult::old_version: return "old version";
    case LoadResult::storage_error: return "storage error";
  }
  return "unknown";
}

std::size_t encode_record(const Persisted& p, std::span<std::uint8_t, kRecordSlot> out) {
  for (std::uint8_t& b : out) b = 0xFF;
  proto::ByteWriter w(out);
  w.u32(kRecordMagic);
  w.u8(kRecordVersion);
  w.u8(0);  // length, patched below
  p.config.write(w);
  const Calibration& c = p.calibration;
  put_floats(w, c.baseline);
  put_floats(w, c.reference);
  put_floats(w, c.cocontraction);
  w.u16(c.baseline_mask);
  w.u16(c.reference_mask);
  w.u8(c.cocontraction_mask);
  const std::size_t body = w.size();
  out[5] = static_cast<std::uint8_t>(body - kHeader);
  w.u16(proto::crc16_ccitt(std::span<const std::uint8_t>(out).first(body)));
  return w.size();
}

LoadResult decode_record(std::span<const std::uint8_t, kRecordSlot> slot, Persisted& out) {
  proto::ByteReader r(slot);
  if (r.u32() != kRecordMagic) return LoadResult::corrupt;
  const std::uint8_t version = r.u8();
  const std::uint8_t length = r.u8();
  if (version != kRecordVersion) return LoadResult::old_version;
  if (kHeader + length + 2 > kRecordSlot) return LoadResult::corrupt;
  proto::ByteReader crc_reader(slot.subspan(kHeader + length, 2));
  if (crc_reader.u16() != proto::crc16_ccitt(slot.first(kHeader + length))) return LoadResult::corrupt;

  proto::ByteReader body(slot.subspan(kHeader, length));
  Persisted p;
  if (p.config.read(body) != proto::Error::ok) return LoadResult::corrupt;
  Calibration& c = p.calibration;
  if (!get_floats(body, c.baseline) || !get_floats(body, c.reference) || !get_floats(body, c.cocontraction)) {
    return LoadResult::corrupt;
  }
  c.baseline_mask = body.u16();
  c.reference_mask = body.u16();
  c.cocontraction_mask = body.u8();
  if (!body.ok()) return LoadResult::corrupt;
  out = p;
  return LoadResult::loaded;
}

LoadResult load_persisted(hal::Storage& storage, Persisted& out) {
  const std::size_t slots = storage.size() / kRecordSlot;
  LoadResult worst = LoadResult::empty;
  bool found = false;
  Persisted best{};
  std::array<std::uint8_t, kRecordSlot> slot{};
  for (std::size_t k = 0; k < slots; ++k) {
    if (!storage.read(k * kRecordSlot, slot)) return LoadResult::storage_error;
    if (erased(slot)) break;  // the log ends at the first erased slot
    Persisted p;
    const LoadResult r = decode_record(slot, p);
    if (r == LoadResult::loaded) {
      best = p;
      found = true;
    } else if (worst == LoadResult::empty || r == LoadResult::old_version) {
      worst = r;
    }
  }
  if (!found) return worst;
  out = best;
  return LoadResult::loaded;
}

bool save_persisted(hal::Storage& storage, const Persisted& p) {
  const std::size_t slots = storage.size() / kRecordSlot;
  if (slots == 0) return false;
  std::array<std::uint8_t, kRecordSlot> slot{};
  std::size_t free_slot = slots;
  for (std::size_t k = 0; k < slots; ++k) {
    if (!storage.read(k * kRecordSlot, slot)) return false;
    if (erased(slot)) {
      free_slot = k;
      break;
    }
  }
  if (free_slot == slots) {
    if (!storage.erase()) return false;
    free_slot = 0;
  }
  std::array<std::uint8_t, kRecordSlot> record{};
  encode_record(p, record);
  if (!storage.program(free_slot * kRecordSlot, record)) return false;
  if (!storage.read(free_slot * kRecordSlot, slot)) return false;
  return slot == record;
}

bool erase_persisted(hal::Storage& storage) { return storage.erase(); }

}  // namespace tonus::fw
