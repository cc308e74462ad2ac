// The persisted state of the band (configuration + calibration) and its
// record log in flash-like storage of two (or more) erase sectors.
//
// Record version 2 (little-endian, 256-byte slots):
//   u32 magic 'TNUS' | u8 version | u8 payload length | payload | u16 CRC-16/CCITT-FALSE
//   payload = u32 generation | u8 config length | DeviceConfig (protocol wire form) | baseline f32[8]
//             | reference f32[8] | cocontraction f32[4] | u16 baseline_mask
//             | u16 reference_mask | u8 cocontraction_mask | u32 boot_count
// Version 1 (128-byte slots, no generation) is still read, as generation 0.
//
// Saving appends the next generation to the sector that holds the newest
// record. When that sector is full, the other one is erased and the record
// goes to its first slot: the newest copy is never erased before a newer one
// is written and verified, so a power cut at any instant leaves a valid record
// (the new one, or the one before). Loading takes the valid record with the
// highest generation in any sector; a torn or corrupt record is skipped, and
// no valid record at all gives defaults (reported as "not calibrated").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/firmware/calibration.hpp"
#include "tonus/hal/storage.hpp"
#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr std::uint32_t kRecordMagic = 0x53554E54;  // "TNUS"
inline constexpr std::uint8_t kRecordVersion = 2;
inline constexpr std::size_t kRecordSlot = 256;
inline constexpr std::uint8_t kRecordVersion1 = 1;  // read only
inline constexpr std::size_t kRecordSlot1 = 128;

struct Persisted {
  proto::DeviceConfig config{};
  Calibration calibration{};
  std::uint32_t boot_count = 0;  // boots since the storage was erased (version 2 only)
  friend bool operator==(const Persisted&, const Persisted&) = default;
};

enum class LoadResult : std::uint8_t {
  loaded,         // a valid record was found
  empty,          // storage erased: defaults
  corrupt,        // records present but none valid (CRC, magic, length): defaults
  old_version,    // only records of another version: defaults
  storage_error,  // the storage could not be read: defaults
};

const char* to_string(LoadResult r);

// Serialises one record into a slot buffer; returns its size (<= kRecordSlot).
std::size_t encode_record(const Persisted& p, std::uint32_t generation, std::span<std::uint8_t, kRecordSlot> out);
// Checks and reads one record at the front of `slot` (version 2, or version 1
// with generation 0).
LoadResult decode_record(std::span<const std::uint8_t> slot, Persisted& out, std::uint32_t& generation);

// Loads the newest valid record; `out` is left untouched unless it returns loaded.
LoadResult load_persisted(hal::Storage& storage, Persisted& out);
// Writes the next generation and verifies it by reading it back.
bool save_persisted(hal::Storage& storage, const Persisted& p);
// Erases every sector (factory defaults).
bool erase_persisted(hal::Storage& storage);

}  // namespace tonus::fw
