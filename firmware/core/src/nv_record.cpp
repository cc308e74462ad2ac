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

std::size_t encode_record(const Persisted& p, std::uint32_t generation, std::span<std::uint8_t, kRecordSlot> out) {
  for (std::uint8_t& b : out) b = 0xFF;
  proto::ByteWriter w(out);
  w.u32(kRecordMagic);
  w.u8(kRecordVersion);
  w.u8(0);  // length, patched below
  w.u32(generation);
  w.u8(static_cast<std::uint8_t>(proto::DeviceConfig::kWireSize));
  p.config.write(w);
  const Calibration& c = p.calibration;
  put_floats(w, c.baseline);
  put_floats(w, c.reference);
  put_floats(w, c.cocontraction);
  w.u16(c.baseline_mask);
  w.u16(c.reference_mask);
  w.u8(c.cocontraction_mask);
  w.u32(p.boot_count);
  const std::size_t body = w.size();
  out[5] = static_cast<std::uint8_t>(body - kHeader);
  w.u16(proto::crc16_ccitt(std::span<const std::uint8_t>(out).first(body)));
  return w.size();
}

LoadResult decode_record(std::span<const std::uint8_t> slot, Persisted& out, std::uint32_t& generation) {
  if (slot.size() < kHeader + 2) return LoadResult::corrupt;
  proto::ByteReader r(slot);
  if (r.u32() != kRecordMagic) return LoadResult::corrupt;
  const std::uint8_t version = r.u8();
  const std::uint8_t length = r.u8();
  // Every version keeps this header and ends with the CRC: a record that fails
  // it is torn or corrupt, whatever its version byte says.
  if (kHeader + length + 2 > slot.size()) return LoadResult::corrupt;
  proto::ByteReader crc_reader(slot.subspan(kHeader + length, 2));
  if (crc_reader.u16() != proto::crc16_ccitt(slot.first(kHeader + length))) return LoadResult::corrupt;
  if (version != kRecordVersion && version != kRecordVersion1) return LoadResult::old_version;
  const std::size_t slot_size = version == kRecordVersion ? kRecordSlot : kRecordSlot1;
  if (kHeader + length + 2 > slot_size) return LoadResult::corrupt;

  proto::ByteReader body(slot.subspan(kHeader, length));
  const std::uint32_t gen = version == kRecordVersion ? body.u32() : 0U;
  // The configuration's own length (version 2), so that a record written with a
  // longer or shorter DeviceConfig (another minor) still reads; version 1 kept
  // the minor-0 form.
  const std::size_t config_size = version == kRecordVersion ? body.u8() : proto::DeviceConfig::kMinWireSize;
  std::array<std::uint8_t, 255> config_bytes{};
  if (config_size < proto::DeviceConfig::kMinWireSize) return LoadResult::corrupt;
  body.bytes(std::span<std::uint8_t>(config_bytes).first(config_size));
  if (!body.ok()) return LoadResult::corrupt;
  proto::ByteReader config_reader(std::span<const std::uint8_t>(config_bytes).first(config_size));
  Persisted p;
  if (p.config.read(config_reader) != proto::Error::ok) return LoadResult::corrupt;
  Calibration& c = p.calibration;
  if (!get_floats(body, c.baseline) || !get_floats(body, c.reference) || !get_floats(body, c.cocontraction)) {
    return LoadResult::corrupt;
  }
  c.baseline_mask = body.u16();
  c.reference_mask = body.u16();
  c.cocontraction_mask = body.u8();
  if (version == kRecordVersion) p.boot_count = body.u32();
  if (!body.ok()) return LoadResult::corrupt;
  out = p;
  generation = gen;
  return LoadResult::loaded;
}

namespace {

// What one sector holds.
struct SectorScan {
  bool readable = true;
  bool found = false;            // a valid record
  std::uint32_t generation = 0;  // of the newest valid record
  Persisted newest{};
  LoadResult worst = LoadResult::empty;  // what the invalid slots were, if nothing valid
  std::size_t free_slot = 0;             // first slot after the last written one (== slots: full)
  std::size_t slots = 0;
};

SectorScan scan_sector(hal::Storage& storage, std::size_t sector) {
  SectorScan s;
  const std::size_t base = sector * storage.sector_size();
  std::array<std::uint8_t, kRecordSlot> slot{};
  // A sector written by version 1 firmware holds 128-byte slots: read them,
  // and never append to it (it counts as full).
  std::array<std::uint8_t, kHeader> head{};
  if (!storage.read(base, head)) {
    s.readable = false;
    return s;
  }
  const bool v1 = head[4] == kRecordVersion1 && proto::ByteReader(head).u32() == kRecordMagic;
  const std::size_t slot_size = v1 ? kRecordSlot1 : kRecordSlot;
  s.slots = storage.sector_size() / slot_size;
  const auto bytes = std::span<std::uint8_t>(slot).first(slot_size);
  for (std::size_t k = 0; k < s.slots; ++k) {
    if (!storage.read(base + k * slot_size, bytes)) {
      s.readable = false;
      return s;
    }
    if (erased(bytes)) continue;
    s.free_slot = k + 1;
    Persisted p;
    std::uint32_t gen = 0;
    const LoadResult r = decode_record(bytes, p, gen);
    if (r == LoadResult::loaded) {
      if (!s.found || gen >= s.generation) {
        s.newest = p;
        s.generation = gen;
      }
      s.found = true;
    } else if (s.worst == LoadResult::empty || r == LoadResult::old_version) {
      s.worst = r;
    }
  }
  if (v1) s.free_slot = s.slots;
  return s;
}

// The sector whose record is the newest; sector_count() if none holds one.
std::size_t newest_sector(std::span<const SectorScan> scans) {
  std::size_t best = scans.size();
  for (std::size_t k = 0; k < scans.size(); ++k) {
    if (scans[k].found && (best == scans.size() || scans[k].generation > scans[best].generation)) best = k;
  }
  return best;
}

constexpr std::size_t kMaxSectors = 4;

}  // namespace

LoadResult load_persisted(hal::Storage& storage, Persisted& out) {
  const std::size_t sectors = storage.sector_count();
  if (sectors == 0 || sectors > kMaxSectors) return LoadResult::storage_error;
  std::array<SectorScan, kMaxSectors> scans{};
  LoadResult worst = LoadResult::empty;
  for (std::size_t s = 0; s < sectors; ++s) {
    scans[s] = scan_sector(storage, s);
    if (!scans[s].readable) return LoadResult::storage_error;
    if (worst == LoadResult::empty || scans[s].worst == LoadResult::old_version) {
      if (scans[s].worst != LoadResult::empty) worst = scans[s].worst;
    }
  }
  const std::size_t best = newest_sector(std::span<const SectorScan>(scans).first(sectors));
  if (best == sectors) return worst;
  out = scans[best].newest;
  return LoadResult::loaded;
}

bool save_persisted(hal::Storage& storage, const Persisted& p) {
  const std::size_t sectors = storage.sector_count();
  if (sectors < 2 || sectors > kMaxSectors || storage.sector_size() < kRecordSlot) return false;
  std::array<SectorScan, kMaxSectors> scans{};
  for (std::size_t s = 0; s < sectors; ++s) {
    scans[s] = scan_sector(storage, s);
    if (!scans[s].readable) return false;
  }
  const std::size_t newest = newest_sector(std::span<const SectorScan>(scans).first(sectors));
  const std::uint32_t generation = newest == sectors ? 1U : scans[newest].generation + 1U;
  // Append beside the newest copy; when its sector is full, start the next
  // sector afresh (the newest copy stays where it is until then).
  std::size_t target = newest == sectors ? 0 : newest;
  std::size_t slot = scans[target].free_slot;
  if (slot >= scans[target].slots) {
    target = (target + 1) % sectors;
    if (!storage.erase(target)) return false;
    slot = 0;
  }
  std::array<std::uint8_t, kRecordSlot> record{};
  encode_record(p, generation, record);
  const std::size_t offset = target * storage.sector_size() + slot * kRecordSlot;
  if (!storage.program(offset, record)) return false;
  std::array<std::uint8_t, kRecordSlot> back{};
  if (!storage.read(offset, back)) return false;
  return back == record;
}

bool erase_persisted(hal::Storage& storage) {
  bool ok = true;
  for (std::size_t s = 0; s < storage.sector_count(); ++s) ok = storage.erase(s) && ok;
  return ok;
}

}  // namespace tonus::fw
