#include "tonus/host/daemon/recording_format.hpp"

#include <zlib.h>

#include <bit>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace tonus::daemon::recording {
namespace {

// --- little-endian writing and reading --------------------------------------

class Out {
 public:
  explicit Out(std::vector<std::uint8_t>& b) : b_(b) {}
  void u8(std::uint8_t v) { b_.push_back(v); }
  void u32(std::uint32_t v) { fixed(v, 4); }
  void u64(std::uint64_t v) { fixed(v, 8); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void varint(std::uint64_t v) {
    while (v >= 0x80U) {
      b_.push_back(static_cast<std::uint8_t>(v | 0x80U));
      v >>= 7U;
    }
    b_.push_back(static_cast<std::uint8_t>(v));
  }
  void zigzag(std::int64_t v) { varint((static_cast<std::uint64_t>(v) << 1U) ^ static_cast<std::uint64_t>(v >> 63)); }
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    b_.insert(b_.end(), c, c + n);
  }

 private:
  void fixed(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b_.push_back(static_cast<std::uint8_t>(v >> (8U * static_cast<unsigned>(i))));
  }
  std::vector<std::uint8_t>& b_;
};

class In {
 public:
  explicit In(std::span<const std::uint8_t> b) : b_(b) {}
  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] bool at_end() const { return pos_ == b_.size(); }
  std::uint8_t u8() { return static_cast<std::uint8_t>(fixed(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(fixed(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(fixed(4)); }
  std::uint64_t u64() { return fixed(8); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64() { return std::bit_cast<double>(u64()); }
  std::uint64_t varint() {
    std::uint64_t v = 0;
    for (unsigned shift = 0; shift < 64; shift += 7) {
      const std::uint8_t byte = u8();
      if (!ok_) return 0;
      v |= static_cast<std::uint64_t>(byte & 0x7FU) << shift;
      if ((byte & 0x80U) == 0) return v;
    }
    ok_ = false;  // more than ten bytes
    return 0;
  }
  std::int64_t zigzag() {
    const std::uint64_t v = varint();
    return static_cast<std::int64_t>((v >> 1U) ^ (~(v & 1U) + 1U));
  }
  // A count that cannot exceed what is left, at `min_bytes` per item.
  std::size_t count(std::size_t min_bytes) {
    const std::uint64_t n = varint();
    if (!ok_ || n > (b_.size() - pos_) / std::max<std::size_t>(1, min_bytes)) {
      ok_ = false;
      return 0;
    }
    return static_cast<std::size_t>(n);
  }

 private:
  std::uint64_t fixed(int n) {
    if (!ok_ || b_.size() - pos_ < static_cast<std::size_t>(n)) {
      ok_ = false;
      return 0;
    }
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(b_[pos_++]) << (8U * static_cast<unsigned>(i));
    return v;
  }
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

std::uint32_t crc32_of(std::span<const std::uint8_t> b) {
  uLong c = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large payloads in pieces.
  for (std::size_t off = 0; off < b.size();) {
    const std::size_t n = std::min<std::size_t>(b.size() - off, std::numeric_limits<uInt>::max());
    c = crc32(c, b.data() + off, static_cast<uInt>(n));
    off += n;
  }
  return static_cast<std::uint32_t>(c);
}

void put_levels(Out& o, const Levels& l) {
  for (const double v : l) o.f64(v);
}
void get_levels(In& in, Levels& l) {
  for (double& v : l) v = in.f64();
}
void put_vec3(Out& o, const sim::Vec3& v) {
  for (int i = 0; i < 3; ++i) o.f64(v[i]);
}
void get_vec3(In& in, sim::Vec3& v) {
  for (int i = 0; i < 3; ++i) v[i] = in.f64();
}

bool get_bone(In& in, sim::Bone& b) {
  const std::uint8_t v = in.u8();
  if (v >= sim::kBoneCount) return false;
  b = static_cast<sim::Bone>(v);
  return true;
}

void put_band(Out& o, const BandSample& s) {
  o.i64(s.arrival_us);
  o.i64(s.sampled_host_us);
  put_levels(o, s.levels);
  o.u32(s.sequence);
}
void get_band(In& in, BandSample& s) {
  s.arrival_us = in.i64();
  s.sampled_host_us = in.i64();
  get_levels(in, s.levels);
  s.sequence = static_cast<std::uint16_t>(in.u32());
}

void put_pose(Out& o, const PoseSample& s, int nq) {
  o.i64(s.t_us);
  o.u8(s.cut ? 1 : 0);
  for (int i = 0; i < nq; ++i) o.f64(s.qpos[static_cast<std::size_t>(i)]);
}
void get_pose(In& in, PoseSample& s, int nq) {
  s.t_us = in.i64();
  s.cut = in.u8() != 0;
  s.qpos.fill(0.0);
  for (int i = 0; i < nq; ++i) s.qpos[static_cast<std::size_t>(i)] = in.f64();
}

void put_command(Out& o, const Command& c) {
  o.u8(static_cast<std::uint8_t>(c.kind));
  o.u32(c.id);
  o.u8(static_cast<std::uint8_t>(c.gift));
  o.u8(static_cast<std::uint8_t>(c.ball.target));
  for (const double v : {c.ball.mass_kg, c.ball.radius_m, c.ball.speed_mps}) o.f64(v);
  put_vec3(o, c.ball.direction);
  for (const double v : {c.ball.distance_m, c.ball.restitution, c.ball.friction, c.ball.lifetime_s}) o.f64(v);
  o.u8(static_cast<std::uint8_t>(c.cube.target));
  for (const double v : {c.cube.mass_kg, c.cube.edge_m, c.cube.height_m, c.cube.friction, c.cube.lifetime_s}) o.f64(v);
  put_levels(o, c.levels);
}
bool get_command(In& in, Command& c) {
  const std::uint8_t kind = in.u8();
  if (kind > static_cast<std::uint8_t>(Command::Kind::stiffness_release)) return false;
  c.kind = static_cast<Command::Kind>(kind);
  c.id = in.u32();
  const std::uint8_t gift = in.u8();
  if (gift > static_cast<std::uint8_t>(GiftKind::cube)) return false;
  c.gift = static_cast<GiftKind>(gift);
  if (!get_bone(in, c.ball.target)) return false;
  c.ball.mass_kg = in.f64();
  c.ball.radius_m = in.f64();
  c.ball.speed_mps = in.f64();
  get_vec3(in, c.ball.direction);
  c.ball.distance_m = in.f64();
  c.ball.restitution = in.f64();
  c.ball.friction = in.f64();
  c.ball.lifetime_s = in.f64();
  if (!get_bone(in, c.cube.target)) return false;
  c.cube.mass_kg = in.f64();
  c.cube.edge_m = in.f64();
  c.cube.height_m = in.f64();
  c.cube.friction = in.f64();
  c.cube.lifetime_s = in.f64();
  get_levels(in, c.levels);
  return true;
}

constexpr std::size_t kBandBytes = 8 + 8 + 4 * 8 + 4;

}  // namespace

std::uint64_t hash_bytes(std::uint64_t h, const void* data, std::size_t size) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

std::vector<std::uint8_t> encode_header(const Header& h) {
  const nlohmann::json j{{"format", "tonus-recording"},
                         {"version", kVersion},
                         {"config_toml", h.config_toml},
                         {"rate_hz", h.rate_hz},
                         {"nq", h.nq},
                         {"created_utc", h.created_utc},
                         {"tonus_version", h.tonus_version}};
  const std::string text = j.dump(2) + "\n";
  std::vector<std::uint8_t> b;
  Out o(b);
  o.bytes(kFileMagic, sizeof kFileMagic);
  o.u32(kVersion);
  o.u32(static_cast<std::uint32_t>(text.size()));
  o.bytes(text.data(), text.size());
  o.u32(crc32_of({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}));
  return b;
}

bool decode_header_json(std::span<const std::uint8_t> json, Header& out, std::string& error) {
  const nlohmann::json j = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    error = "the header is not JSON";
    return false;
  }
  try {
    if (j.at("format").get<std::string>() != "tonus-recording") {
      error = "the header's format is not tonus-recording";
      return false;
    }
    out.config_toml = j.at("config_toml").get<std::string>();
    out.rate_hz = j.at("rate_hz").get<double>();
    out.nq = j.at("nq").get<int>();
    out.created_utc = j.value("created_utc", "");
    out.tonus_version = j.value("tonus_version", "");
  } catch (const nlohmann::json::exception& e) {
    error = fmt::format("the header misses a field or has a wrong type ({})", e.what());
    return false;
  }
  if (out.nq <= 0 || out.nq > static_cast<int>(sim::kMaxQpos)) {
    error = fmt::format("the header's nq = {} is outside 1..{}", out.nq, sim::kMaxQpos);
    return false;
  }
  if (!(out.rate_hz > 0.0) || out.rate_hz > 100000.0) {
    error = fmt::format("the header's rate_hz = {} is not a physics rate", out.rate_hz);
    return false;
  }
  return true;
}

std::vector<std::uint8_t> encode_chunk(const Chunk& c, int nq) {
  std::vector<std::uint8_t> payload;
  Out o(payload);
  o.u64(c.first_tick);
  o.u32(static_cast<std::uint32_t>(c.ticks.size()));
  const std::int64_t first_us = c.ticks.empty() ? 0 : c.ticks.front().now_us;
  o.i64(first_us);
  o.u64(c.pose_hash);
  o.u32(static_cast<std::uint32_t>(c.vmc_ticks.size()));
  std::uint64_t prev_vmc = 0;
  for (const std::uint64_t t : c.vmc_ticks) {
    o.zigzag(static_cast<std::int64_t>(t - prev_vmc));
    prev_vmc = t;
  }
  std::int64_t prev_us = first_us;
  for (const TickInputs& t : c.ticks) {
    o.zigzag(t.now_us - prev_us);
    prev_us = t.now_us;
    o.varint(t.band.size());
    o.varint(t.poses.size());
    o.varint(t.commands.size());
    for (const BandSample& b : t.band) put_band(o, b);
    for (const PoseSample& p : t.poses) put_pose(o, p, nq);
    for (const Command& cmd : t.commands) put_command(o, cmd);
  }
  std::vector<std::uint8_t> b;
  b.reserve(payload.size() + 12);
  Out head(b);
  head.bytes(kChunkMagic, sizeof kChunkMagic);
  head.u32(static_cast<std::uint32_t>(payload.size()));
  head.u32(crc32_of(payload));
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

bool decode_chunk_payload(std::span<const std::uint8_t> payload, int nq, Chunk& out, std::string& error) {
  In in(payload);
  out.first_tick = in.u64();
  const std::uint32_t ticks = in.u32();
  const std::int64_t first_us = in.i64();
  out.pose_hash = in.u64();
  const std::uint32_t vmc = in.u32();
  if (!in.ok() || vmc > payload.size() || ticks > payload.size()) {
    error = "the chunk's counts exceed its size";
    return false;
  }
  out.vmc_ticks.resize(vmc);
  std::uint64_t prev_vmc = 0;
  for (std::uint64_t& t : out.vmc_ticks) {
    t = prev_vmc + static_cast<std::uint64_t>(in.zigzag());
    prev_vmc = t;
  }
  out.ticks.resize(ticks);
  std::int64_t prev_us = first_us;
  const std::size_t pose_bytes = 9 + 8 * static_cast<std::size_t>(nq);
  for (std::size_t k = 0; k < out.ticks.size() && in.ok(); ++k) {
    TickInputs& t = out.ticks[k];
    t.now_us = prev_us + in.zigzag();
    prev_us = t.now_us;
    t.band.resize(in.count(kBandBytes));
    t.poses.resize(in.count(pose_bytes));
    t.commands.resize(in.count(1));
    for (BandSample& b : t.band) get_band(in, b);
    for (PoseSample& p : t.poses) get_pose(in, p, nq);
    for (Command& c : t.commands) {
      if (!get_command(in, c)) {
        error = fmt::format("tick {} of the chunk holds a command that does not decode", k);
        return false;
      }
    }
  }
  if (!in.ok() || !in.at_end()) {
    error = in.ok() ? "the chunk has bytes after its last tick" : "the chunk ends inside a record";
    return false;
  }
  return true;
}

// --- Reader ------------------------------------------------------------------

std::optional<Reader> Reader::open(const std::string& path, std::string& error) {
  Reader r;
  r.file_ = std::fopen(path.c_str(), "rb");
  if (r.file_ == nullptr) {
    error = fmt::format("{}: {}", path, std::strerror(errno));
    return std::nullopt;
  }
  std::uint8_t head[16];
  if (std::fread(head, 1, sizeof head, r.file_) != sizeof head || std::memcmp(head, kFileMagic, 8) != 0) {
    error = fmt::format("{}: not a tonus recording (no TONUSREC header)", path);
    return std::nullopt;
  }
  In in({head + 8, 8});
  const std::uint32_t version = in.u32();
  const std::uint32_t length = in.u32();
  if (version != kVersion) {
    error = fmt::format("{}: recording format version {}, this tonusd reads version {}", path, version, kVersion);
    return std::nullopt;
  }
  if (length > kMaxHeaderBytes) {
    error = fmt::format("{}: the header claims {} bytes (corrupt)", path, length);
    return std::nullopt;
  }
  std::vector<std::uint8_t> json(length + 4U);
  if (std::fread(json.data(), 1, json.size(), r.file_) != json.size()) {
    error = fmt::format("{}: the file ends inside its header", path);
    return std::nullopt;
  }
  In crc_in({json.data() + length, 4});
  const std::span<const std::uint8_t> text(json.data(), length);
  if (crc_in.u32() != crc32_of(text)) {
    error = fmt::format("{}: the header's checksum does not match (corrupt)", path);
    return std::nullopt;
  }
  if (std::string e; !decode_header_json(text, r.header_, e)) {
    error = fmt::format("{}: {}", path, e);
    return std::nullopt;
  }
  r.offset_ = 16 + json.size();
  r.first_chunk_offset_ = r.offset_;
  return r;
}

bool Reader::rewind() {
  if (std::fseek(file_, static_cast<long>(first_chunk_offset_), SEEK_SET) != 0) return false;
  offset_ = first_chunk_offset_;
  chunks_ = 0;
  error_.clear();
  return true;
}

double Reader::duration_s() {
  const long here = std::ftell(file_);
  std::int64_t first_us = 0, last_us = 0;
  std::uint64_t last_ticks = 0;
  bool any = false;
  if (std::fseek(file_, static_cast<long>(first_chunk_offset_), SEEK_SET) == 0) {
    for (;;) {
      std::uint8_t head[12 + 24];  // marker, length, CRC; first tick, tick count, first time
      if (std::fread(head, 1, sizeof head, file_) != sizeof head || std::memcmp(head, kChunkMagic, 4) != 0) break;
      In in({head + 4, sizeof head - 4});
      const std::uint32_t length = in.u32();
      (void)in.u32();
      (void)in.u64();
      last_ticks = in.u32();
      last_us = in.i64();
      if (!any) first_us = last_us;
      any = true;
      if (length < 24 || std::fseek(file_, static_cast<long>(length) - 24, SEEK_CUR) != 0) break;
    }
  }
  std::fseek(file_, here, SEEK_SET);
  if (!any) return 0.0;
  return static_cast<double>(last_us - first_us) * 1e-6 + static_cast<double>(last_ticks) / header_.rate_hz;
}

Reader::Reader(Reader&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)),
      header_(std::move(other.header_)),
      error_(std::move(other.error_)),
      chunks_(other.chunks_),
      offset_(other.offset_),
      first_chunk_offset_(other.first_chunk_offset_),
      buffer_(std::move(other.buffer_)) {}

Reader& Reader::operator=(Reader&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = std::exchange(other.file_, nullptr);
    header_ = std::move(other.header_);
    error_ = std::move(other.error_);
    chunks_ = other.chunks_;
    offset_ = other.offset_;
    first_chunk_offset_ = other.first_chunk_offset_;
    buffer_ = std::move(other.buffer_);
  }
  return *this;
}

Reader::~Reader() {
  if (file_ != nullptr) std::fclose(file_);
}

Reader::Status Reader::next(Chunk& out) {
  std::uint8_t head[12];
  const std::size_t got = std::fread(head, 1, sizeof head, file_);
  if (got == 0) return Status::end;
  if (got < sizeof head) return Status::truncated;
  if (std::memcmp(head, kChunkMagic, 4) != 0) {
    error_ = fmt::format("chunk {} at byte {}: no chunk marker (corrupt)", chunks_ + 1, offset_);
    return Status::corrupt;
  }
  In in({head + 4, 8});
  const std::uint32_t length = in.u32();
  const std::uint32_t crc = in.u32();
  if (length > kMaxChunkBytes) {
    error_ = fmt::format("chunk {} at byte {}: claims {} bytes (corrupt)", chunks_ + 1, offset_, length);
    return Status::corrupt;
  }
  buffer_.resize(length);
  if (std::fread(buffer_.data(), 1, length, file_) != length) return Status::truncated;
  if (crc32_of(buffer_) != crc) {
    error_ = fmt::format("chunk {} at byte {}: checksum mismatch (corrupt)", chunks_ + 1, offset_);
    return Status::corrupt;
  }
  if (std::string e; !decode_chunk_payload(buffer_, header_.nq, out, e)) {
    error_ = fmt::format("chunk {} at byte {}: {}", chunks_ + 1, offset_, e);
    return Status::corrupt;
  }
  offset_ += sizeof head + length;
  ++chunks_;
  return Status::chunk;
}

}  // namespace tonus::daemon::recording
