// The persisted state of the band (configuration + calibration) and its
// append-only log in flash-like storage.
//
// Record (little-endian, 128-byte slots):
//   u32 magic 'TNUS' | u8 version | u8 payload length | payload | u16 CRC-16/CCITT-FALSE
//   payload = DeviceConfig (protocol wire form) | baseline f32[8] | reference f32[8]
//             | cocontraction f32[4] | u16 baseline_mask | u16 reference_mask | u8 cocontraction_mask
// Saving appends a record in the next erased slot (erasing the area only when
// it is full: one erase per 128 saves). Loading takes the last slot whose
// magic, version, length, CRC and configuration check out; a torn or corrupt
// newest record therefore falls back to the one before, and no valid record
// at all falls back to defaults (reported as "not calibrated").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/firmware/calibration.hpp"
#include "tonus/hal/storage.hpp"
#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr std::uint32_t kRecordMagic = 0x53554E54;  // "TNUS"
inline constexpr std::uint8_t kRecordVersion = 1;
inline constexpr std::size_t kRecordSlot = 128;

struct Persisted {
  proto::DeviceConfig config{};
  Calibration calibration{};
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
std::size_t encode_record(const Persisted& p, std::span<std::uint8_t, kRecordSlot> out);
// Checks and reads one slot. group_count / front end are used to re-check the configuration.
LoadResult decode_record(std::span<const std::uint8_t, kRecordSlot> slot, Persisted& out);

// Loads the newest valid record; `out` is left untouched unless it returns loaded.
LoadResult load_persisted(hal::Storage& storage, Persisted& out);
// Appends a record and verifies it by reading it back.
bool save_persisted(hal::Storage& storage, const Persisted& p);
// Erases the area (factory defaults).
bool erase_persisted(hal::Storage& storage);

}  // namespace tonus::fw
