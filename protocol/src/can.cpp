#include "tonus/protocol/can.hpp"

#include "tonus/protocol/wire.hpp"

namespace tonus::proto::can {

namespace {

constexpr std::uint32_t kFunctionStep = 0x20;

// Index of a stream data function (levels0 .. envelope3) in 0..5.
constexpr std::size_t data_index(Function f) {
  return (static_cast<std::uint32_t>(f) - static_cast<std::uint32_t>(Function::levels0)) / kFunctionStep;
}
constexpr Function data_function(std::size_t index) {
  return static_cast<Function>(static_cast<std::uint32_t>(Function::levels0) + kFunctionStep * index);
}
constexpr std::size_t kLevelFrames = 2;  // levels0, levels1
constexpr std::size_t kEnvelopeFrames = 4;

constexpr std::size_t frames_for(std::size_t values, std::size_t per_frame) {
  return (values + per_frame - 1) / per_frame;
}
constexpr std::size_t values_in_frame(std::size_t values, std::size_t per_frame, std::size_t k) {
  const std::size_t left = values - k * per_frame;
  return left < per_frame ? left : per_frame;
}

CanFrame frame_for(Function f, std::uint8_t node, std::uint32_t id_base) {
  CanFrame fr{};
  fr.id = make_id(f, node, id_base);
  if (id_base != 0) fr.flags = CanFrame::kExtended;
  return fr;
}

// Writes u16 values into one frame and sets its dlc.
void put_values(CanFrame& fr, std::span<const std::uint16_t> values) {
  ByteWriter w(fr.data);
  for (std::uint16_t v : values) w.u16(v);
  fr.dlc = static_cast<std::uint8_t>(w.size());
}

}  // namespace

bool split_id(std::uint32_t id, Function& f, std::uint8_t& node) {
  if (id > 0x7FF) return false;
  const std::uint32_t base = id & ~kNodeMask;
  switch (static_cast<Function>(base)) {
    case Function::status:
    case Function::levels0:
    case Function::levels1:
    case Function::envelope0:
    case Function::envelope1:
    case Function::envelope2:
    case Function::envelope3:
    case Function::flags:
    case Function::response:
    case Function::request:
    case Function::heartbeat:
      f = static_cast<Function>(base);
      node = static_cast<std::uint8_t>(id & kNodeMask);
      return true;
  }
  return false;
}

bool split_frame(const CanFrame& frame, std::uint32_t id_base, Function& f, std::uint8_t& node) {
  const bool extended = (frame.flags & CanFrame::kExtended) != 0;
  if ((frame.flags & (CanFrame::kRemote | CanFrame::kErrorFrame)) != 0 || extended != (id_base != 0)) return false;
  if ((frame.id & ~std::uint32_t{0x7FF}) != id_base) return false;  // the base's bits, exactly
  return split_id(frame.id - id_base, f, node);
}

Error encode_stream(const StreamMessage& msg, std::uint8_t node, bool with_envelopes, std::span<CanFrame> out,
                    std::size_t& count, std::uint32_t id_base) {
  count = 0;
  if (node > kMaxNodeId || !valid_id_base(id_base)) return Error::bad_value;
  if (Error e = validate(msg); e != Error::ok) return e;
  const std::size_t level_frames = frames_for(msg.group_count, kGroupsPerFrame);
  const std::size_t env_frames = with_envelopes ? frames_for(msg.channel_count, kChannelsPerFrame) : 0;
  if (out.size() < 2 + level_frames + env_frames) return Error::buffer_too_small;

  std::size_t n = 0;
  CanFrame status = frame_for(Function::status, node, id_base);
  ByteWriter ws(status.data);
  ws.u16(msg.sequence);
  ws.u32(msg.device_time_us);
  ws.u16(static_cast<std::uint16_t>((msg.status & (0xFFFFU ^ kStatusEnvelopesFollow)) |
                                    (env_frames != 0 ? kStatusEnvelopesFollow : 0U)));
  status.dlc = 8;
  out[n++] = status;

  for (std::size_t k = 0; k < level_frames; ++k) {
    CanFrame fr = frame_for(data_function(k), node, id_base);
    put_values(
        fr, std::span(msg.levels).subspan(k * kGroupsPerFrame, values_in_frame(msg.group_count, kGroupsPerFrame, k)));
    out[n++] = fr;
  }
  for (std::size_t k = 0; k < env_frames; ++k) {
    CanFrame fr = frame_for(data_function(kLevelFrames + k), node, id_base);
    put_values(fr, std::span(msg.envelopes)
                       .subspan(k * kChannelsPerFrame, values_in_frame(msg.channel_count, kChannelsPerFrame, k)));
    out[n++] = fr;
  }

  CanFrame flags = frame_for(Function::flags, node, id_base);
  ByteWriter wf(flags.data);
  wf.u16(msg.electrode_off);
  wf.u16(msg.saturation);
  wf.u16(msg.artifact);
  wf.u8(static_cast<std::uint8_t>(((msg.group_count - 1U) << 4U) | (msg.channel_count - 1U)));
  wf.u8(static_cast<std::uint8_t>(msg.sequence));
  flags.dlc = 8;
  out[n++] = flags;
  count = n;
  return Error::ok;
}

void StreamAssembler::abandon_cycle() {
  in_cycle_ = false;
  seen_ = 0;
}

Error StreamAssembler::push(const CanFrame& frame, bool& complete) {
  complete = false;
  Function f{};
  std::uint8_t node = 0;
  // Other traffic on a shared bus is normal: ignore it quietly.
  if (!split_frame(frame, id_base_, f, node) || node != node_) return Error::ok;
  if (frame.dlc > 8) return Error::bad_length;

  switch (f) {
    case Function::status: {
      if (in_cycle_) ++incomplete_cycles_;
      abandon_cycle();
      if (frame.dlc != 8) return Error::bad_length;
      ByteReader r(frame.payload());
      pending_ = StreamMessage{};
      pending_.sequence = r.u16();
      pending_.device_time_us = r.u32();
      pending_.status = r.u16();
      envelopes_expected_ = (pending_.status & kStatusEnvelopesFollow) != 0;
      pending_.status = static_cast<std::uint16_t>(pending_.status & (0xFFFFU ^ kStatusEnvelopesFollow));
      in_cycle_ = true;
      return Error::ok;
    }
    case Function::levels0:
    case Function::levels1:
    case Function::envelope0:
    case Function::envelope1:
    case Function::envelope2:
    case Function::envelope3: {
      if (!in_cycle_) {
        ++stray_frames_;
        return Error::ok;
      }
      const std::size_t index = data_index(f);
      const auto bit = static_cast<std::uint8_t>(1U << index);
      const bool is_level = index < kLevelFrames;
      const std::size_t first = (is_level ? index : index - kLevelFrames) * 4;
      const std::size_t capacity = is_level ? kMaxGroups : kMaxChannels;
      const std::size_t values = frame.dlc / 2U;
      if ((seen_ & bit) != 0) {
        ++incomplete_cycles_;
        abandon_cycle();
        return Error::out_of_order;
      }
      if (frame.dlc == 0 || frame.dlc % 2 != 0 || first + values > capacity) {
        ++incomplete_cycles_;
        abandon_cycle();
        return Error::bad_length;
      }
      ByteReader r(frame.payload());
      for (std::size_t j = 0; j < values; ++j) {
        (is_level ? pending_.levels[first + j] : pending_.envelopes[first + j]) = r.u16();
      }
      seen_ = static_cast<std::uint8_t>(seen_ | bit);
      dlc_[index] = frame.dlc;
      return Error::ok;
    }
    case Function::flags: {
      if (!in_cycle_) {
        ++stray_frames_;
        return Error::ok;
      }
      const std::uint8_t seen = seen_;
      abandon_cycle();
      if (frame.dlc != 8) {
        ++incomplete_cycles_;
        return Error::bad_length;
      }
      ByteReader r(frame.payload());
      pending_.electrode_off = r.u16();
      pending_.saturation = r.u16();
      pending_.artifact = r.u16();
      const std::uint8_t counts = r.u8();
      const std::uint8_t sequence_low = r.u8();
      pending_.group_count = static_cast<std::uint8_t>((counts >> 4U) + 1U);
      pending_.channel_count = static_cast<std::uint8_t>((counts & 0x0FU) + 1U);
      if (sequence_low != static_cast<std::uint8_t>(pending_.sequence)) {
        ++incomplete_cycles_;
        return Error::out_of_order;
      }
      if (Error e = validate(pending_); e != Error::ok) {
        ++incomplete_cycles_;
        return e;
      }
      // Every levels frame the counts call for, with the right length, and no other.
      const std::size_t level_frames = frames_for(pending_.group_count, kGroupsPerFrame);
      for (std::size_t k = 0; k < kLevelFrames; ++k) {
        const bool expected = k < level_frames;
        const bool got = (seen >> k) & 1U;
        if (expected != got || (got && dlc_[k] != 2 * values_in_frame(pending_.group_count, kGroupsPerFrame, k))) {
          ++incomplete_cycles_;
          return Error::out_of_order;
        }
      }
      // Envelopes are all-or-nothing within a cycle.
      const auto env_seen = static_cast<std::uint8_t>(seen >> kLevelFrames);
      const std::size_t env_frames = frames_for(pending_.channel_count, kChannelsPerFrame);
      if (env_seen != 0) {
        for (std::size_t k = 0; k < kEnvelopeFrames; ++k) {
          const bool expected = k < env_frames;
          const bool got = (env_seen >> k) & 1U;
          if (expected != got ||
              (got && dlc_[kLevelFrames + k] != 2 * values_in_frame(pending_.channel_count, kChannelsPerFrame, k))) {
            ++incomplete_cycles_;
            return Error::out_of_order;
          }
        }
      } else if (envelopes_expected_) {
        // Announced but none arrived: lost, not a cycle sent without them.
        ++incomplete_cycles_;
        return Error::out_of_order;
      } else {
        pending_.envelopes = msg_.envelopes;  // hold the last envelopes
      }
      for (std::size_t g = pending_.group_count; g < kMaxGroups; ++g) pending_.levels[g] = 0;
      for (std::size_t c = pending_.channel_count; c < kMaxChannels; ++c) pending_.envelopes[c] = 0;
      msg_ = pending_;
      envelopes_fresh_ = env_seen != 0;
      complete = true;
      return Error::ok;
    }
    case Function::response:
    case Function::request:
    case Function::heartbeat: return Error::ok;
  }
  return Error::ok;
}

CanFrame encode_heartbeat(const Heartbeat& hb, std::uint8_t node, std::uint32_t id_base) {
  CanFrame fr = frame_for(Function::heartbeat, node, id_base);
  ByteWriter w(fr.data);
  w.u8(static_cast<std::uint8_t>(hb.state));
  w.u8(hb.protocol_version);
  w.u16(hb.status);
  w.u32(hb.uptime_ms);
  fr.dlc = 8;
  return fr;
}

Error decode_heartbeat(const CanFrame& frame, Heartbeat& out, std::uint32_t id_base) {
  Function f{};
  std::uint8_t node = 0;
  if (!split_frame(frame, id_base, f, node) || f != Function::heartbeat) return Error::bad_type;
  if (frame.dlc != 8) return Error::bad_length;
  ByteReader r(frame.payload());
  const std::uint8_t state = r.u8();
  if (state > static_cast<std::uint8_t>(NodeState::fault)) return Error::bad_value;
  Heartbeat hb{};
  hb.state = static_cast<NodeState>(state);
  hb.protocol_version = r.u8();
  hb.status = r.u16();
  hb.uptime_ms = r.u32();
  out = hb;
  return Error::ok;
}

Error segment(std::span<const std::uint8_t> message, Function f, std::uint8_t node, std::span<CanFrame> out,
              std::size_t& count, std::uint32_t id_base) {
  count = 0;
  if (node > kMaxNodeId || !valid_id_base(id_base)) return Error::bad_value;
  if (f != Function::request && f != Function::response) return Error::bad_type;
  if (message.empty() || message.size() > kMaxMessageSize) return Error::bad_length;
  const std::size_t total = frames_for(message.size(), kSegmentData);
  if (out.size() < total) return Error::buffer_too_small;
  for (std::size_t i = 0; i < total; ++i) {
    CanFrame fr = frame_for(f, node, id_base);
    const std::size_t n = values_in_frame(message.size(), kSegmentData, i);
    fr.data[0] = static_cast<std::uint8_t>((total << 4U) | i);
    for (std::size_t j = 0; j < n; ++j) fr.data[1 + j] = message[i * kSegmentData + j];
    fr.dlc = static_cast<std::uint8_t>(1 + n);
    out[i] = fr;
  }
  count = total;
  return Error::ok;
}

void Reassembler::reset() {
  total_ = 0;
  expected_ = 0;
  size_ = 0;
}

Error Reassembler::push(const CanFrame& frame, bool& complete) {
  complete = false;
  Function f{};
  std::uint8_t node = 0;
  if (!split_frame(frame, id_base_, f, node) || f != function_ || node != node_) return Error::ok;
  if (frame.dlc < 2 || frame.dlc > 8) {
    reset();
    return Error::bad_length;
  }
  const auto total = static_cast<std::uint8_t>(frame.data[0] >> 4U);
  const auto index = static_cast<std::uint8_t>(frame.data[0] & 0x0FU);
  if (total == 0 || total > kMaxSegments || index >= total) {
    reset();
    return Error::bad_value;
  }
  if (index == 0) {
    reset();
    total_ = total;
  } else if (total != total_ || index != expected_) {
    reset();
    return Error::out_of_order;
  }
  const bool last = index + 1 == total;
  if (!last && frame.dlc != 8) {  // only the last segment may be short
    reset();
    return Error::bad_length;
  }
  for (std::size_t j = 1; j < frame.dlc; ++j) buffer_[size_++] = frame.data[j];
  expected_ = static_cast<std::uint8_t>(index + 1);
  if (last) {
    complete = true;
    total_ = 0;
    expected_ = 0;  // message() stays valid until the next segment arrives
  }
  return Error::ok;
}

}  // namespace tonus::proto::can
