// The recording file (tonusd --record / --replay), format version 1; every
// byte is described in docs/recording.md.
//
//   header: "TONUSREC", u32 version, u32 length, JSON (the effective config as
//           TOML, the rate, the model's qpos size), u32 CRC-32 of the JSON
//   chunks: "TCHK", u32 payload length, u32 CRC-32 of the payload, payload:
//           u64 first tick, u32 tick count, i64 first tick's time (us),
//           u64 pose hash after the chunk's last tick,
//           u32 VMC frame count, the ticks they were sent from (varint deltas),
//           then per tick: the time (zigzag varint delta), the band reports,
//           tracker poses and commands the tick consumed (counts as varints,
//           then each item, little-endian fixed width, doubles as IEEE bits).
//
// A chunk holds about a second and is written whole and flushed, so a killed
// daemon loses at most that second, and a reader stops cleanly at the last
// whole chunk of a truncated file. A chunk whose CRC does not match is
// corruption: the reader says where and stops.
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tonus/host/daemon/messages.hpp"

namespace tonus::daemon::recording {

inline constexpr std::uint32_t kVersion = 1;
inline constexpr char kFileMagic[8] = {'T', 'O', 'N', 'U', 'S', 'R', 'E', 'C'};
inline constexpr char kChunkMagic[4] = {'T', 'C', 'H', 'K'};
inline constexpr std::size_t kMaxHeaderBytes = 1U << 20U;   // 1 MiB of JSON
inline constexpr std::size_t kMaxChunkBytes = 256U << 20U;  // a chunk larger than this is corruption

struct Header {
  std::string config_toml;  // the effective configuration (parse_config reads it)
  double rate_hz = 1000.0;
  int nq = 0;                 // the model's qpos size: poses carry nq values
  std::string created_utc;    // ISO 8601, informative
  std::string tonus_version;  // informative
};

// What one tick consumed, in the order the core consumed it.
struct TickInputs {
  std::int64_t now_us = 0;
  std::vector<BandSample> band;
  std::vector<PoseSample> poses;
  std::vector<Command> commands;
};

struct Chunk {
  std::uint64_t first_tick = 0;          // the core's tick count after the chunk's first tick (1 for the first chunk)
  std::uint64_t pose_hash = 0;           // PhysicsCore's output hash after the chunk's last tick
  std::vector<std::uint64_t> vmc_ticks;  // snapshots the VMC output sent while the chunk was written, by tick
  std::vector<TickInputs> ticks;
};

// Serialisation (pure; the tests round-trip through these).
std::vector<std::uint8_t> encode_header(const Header& h);
std::vector<std::uint8_t> encode_chunk(const Chunk& c, int nq);

// FNV-1a, 64 bits: the running hashes of the outputs (poses, VMC bytes).
inline constexpr std::uint64_t kHashSeed = 14695981039346656037ULL;
std::uint64_t hash_bytes(std::uint64_t h, const void* data, std::size_t size);

// Reads a recording from the start, chunk by chunk.
class Reader {
 public:
  enum class Status : std::uint8_t { chunk, end, truncated, corrupt };

  // nullopt and `error` when the file cannot be read or its header is bad.
  static std::optional<Reader> open(const std::string& path, std::string& error);
  Reader(Reader&& other) noexcept;
  Reader& operator=(Reader&& other) noexcept;
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
  ~Reader();

  [[nodiscard]] const Header& header() const { return header_; }
  // The next chunk into `out`: `chunk`; `end` at a clean end of file;
  // `truncated` when the file ends inside a chunk (what came before is
  // whole); `corrupt` with error() saying where.
  Status next(Chunk& out);
  [[nodiscard]] const std::string& error() const { return error_; }
  // Back to the first chunk; false if the file cannot be repositioned.
  bool rewind();
  // The recording's length, s (from the chunks' heads; the file position is kept).
  [[nodiscard]] double duration_s();
  [[nodiscard]] std::uint64_t chunks_read() const { return chunks_; }
  [[nodiscard]] std::uint64_t offset() const { return offset_; }

 private:
  Reader() = default;
  std::FILE* file_ = nullptr;
  Header header_;
  std::string error_;
  std::uint64_t chunks_ = 0;
  std::uint64_t offset_ = 0;
  std::uint64_t first_chunk_offset_ = 0;
  std::vector<std::uint8_t> buffer_;
};

// Decodes a chunk's payload (after the CRC check); false and `error` when it
// does not parse (which a good CRC makes a bug or a foreign file).
bool decode_chunk_payload(std::span<const std::uint8_t> payload, int nq, Chunk& out, std::string& error);
// Decodes a header's JSON.
bool decode_header_json(std::span<const std::uint8_t> json, Header& out, std::string& error);

}  // namespace tonus::daemon::recording
