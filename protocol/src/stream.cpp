#include "tonus/protocol/stream.hpp"

#include "tonus/protocol/wire.hpp"

namespace tonus::proto {

namespace {

constexpr std::uint16_t channel_mask(std::size_t channels) {
  return static_cast<std::uint16_t>((1UL << channels) - 1UL);
}

}  // namespace

Error validate(const StreamMessage& msg) {
  if (msg.group_count < 1 || msg.group_count > kMaxGroups) return Error::bad_length;
  if (msg.channel_count < 1 || msg.channel_count > kMaxChannels) return Error::bad_length;
  // Flags for channels that do not exist mean a corrupt or confused sender.
  const std::uint16_t valid = channel_mask(msg.channel_count);
  if (((msg.electrode_off | msg.saturation | msg.artifact) & ~valid) != 0) return Error::bad_value;
  return Error::ok;
}

Error encode_stream(const StreamMessage& msg, std::span<std::uint8_t> out, std::size_t& written) {
  written = 0;
  if (Error e = validate(msg); e != Error::ok) return e;
  ByteWriter w(out);
  w.u8(kProtocolVersion);
  w.u8(msg.group_count);
  w.u8(msg.channel_count);
  w.u8(msg.boot_epoch);
  w.u16(msg.sequence);
  w.u32(msg.device_time_us);
  w.u16(msg.status);
  w.u16(msg.electrode_off);
  w.u16(msg.saturation);
  w.u16(msg.artifact);
  for (std::size_t g = 0; g < msg.group_count; ++g) w.u16(msg.levels[g]);
  for (std::size_t c = 0; c < msg.channel_count; ++c) w.u16(msg.envelopes[c]);
  if (!w.ok()) return w.error();
  written = w.size();
  return Error::ok;
}

Error decode_stream(std::span<const std::uint8_t> in, StreamMessage& out) {
  ByteReader r(in);
  const std::uint8_t version = r.u8();
  if (!r.ok()) return r.error();
  if (version != kProtocolVersion) return Error::bad_version;

  StreamMessage m{};
  m.group_count = r.u8();
  m.channel_count = r.u8();
  m.boot_epoch = r.u8();  // byte 3 was reserved (sent 0) in version 1.0
  m.sequence = r.u16();
  m.device_time_us = r.u32();
  m.status = r.u16();
  m.electrode_off = r.u16();
  m.saturation = r.u16();
  m.artifact = r.u16();
  if (!r.ok()) return r.error();
  if (Error e = validate(m); e != Error::ok) return e;
  for (std::size_t g = 0; g < m.group_count; ++g) m.levels[g] = r.u16();
  for (std::size_t c = 0; c < m.channel_count; ++c) m.envelopes[c] = r.u16();
  if (!r.ok()) return r.error();
  out = m;
  return Error::ok;
}

}  // namespace tonus::proto
