#include "tonus/protocol/command.hpp"

#include "tonus/protocol/crc16.hpp"
#include "tonus/protocol/wire.hpp"

namespace tonus::proto {

bool is_known(Opcode op) {
  switch (op) {
    case Opcode::get_device_info:
    case Opcode::time_sync:
    case Opcode::get_stats:
    case Opcode::get_log:
    case Opcode::calibration_start:
    case Opcode::calibration_abort:
    case Opcode::calibration_status:
    case Opcode::get_config:
    case Opcode::set_config:
    case Opcode::save_config:
    case Opcode::reset:
    case Opcode::enter_bootloader: return true;
  }
  return false;
}

const char* to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::unknown_opcode: return "unknown opcode";
    case Status::bad_length: return "bad payload length";
    case Status::bad_value: return "value out of range";
    case Status::busy: return "busy";
    case Status::wrong_state: return "not allowed in this state";
    case Status::storage_error: return "storage error";
    case Status::bad_version: return "unsupported protocol version";
    case Status::bad_crc: return "request checksum mismatch";
  }
  return "unknown status";
}

namespace {

bool is_known(Status s) { return static_cast<std::uint8_t>(s) <= static_cast<std::uint8_t>(Status::bad_crc); }

// Appends the CRC of everything written so far.
Error finish(ByteWriter& w, std::span<std::uint8_t> out, std::size_t& written) {
  if (!w.ok()) return w.error();
  w.u16(crc16_ccitt(out.first(w.size())));
  if (!w.ok()) return w.error();
  written = w.size();
  return Error::ok;
}

Error check_crc(std::span<const std::uint8_t> in, std::size_t body_size) {
  if (in.size() < body_size + 2) return Error::truncated;
  ByteReader r(in.subspan(body_size, 2));
  return r.u16() == crc16_ccitt(in.first(body_size)) ? Error::ok : Error::bad_crc;
}

}  // namespace

Error encode_request(const Request& req, std::span<std::uint8_t> out, std::size_t& written) {
  written = 0;
  if (req.length > kMaxRequestPayload) return Error::bad_length;
  ByteWriter w(out);
  w.u8(kProtocolVersion);
  w.u8(static_cast<std::uint8_t>(req.opcode));
  w.u8(req.token);
  w.u8(req.length);
  w.bytes(req.body());
  return finish(w, out, written);
}

Error decode_request(std::span<const std::uint8_t> in, Request& out) {
  ByteReader r(in);
  const std::uint8_t version = r.u8();
  const std::uint8_t opcode = r.u8();
  Request req{};
  req.token = r.u8();
  req.length = r.u8();
  if (!r.ok()) return r.error();
  if (version != kProtocolVersion) return Error::bad_version;
  if (opcode & kResponseBit) return Error::bad_type;
  if (req.length > kMaxRequestPayload) return Error::bad_length;
  r.bytes(std::span(req.payload).first(req.length));
  if (!r.ok()) return r.error();
  if (Error e = check_crc(in, r.position()); e != Error::ok) return e;
  req.opcode = static_cast<Opcode>(opcode);
  out = req;
  return Error::ok;
}

Error encode_response(const Response& rsp, std::span<std::uint8_t> out, std::size_t& written) {
  written = 0;
  if (rsp.length > kMaxResponsePayload) return Error::bad_length;
  if (!is_known(rsp.status)) return Error::bad_value;
  ByteWriter w(out);
  w.u8(kProtocolVersion);
  w.u8(static_cast<std::uint8_t>(static_cast<std::uint8_t>(rsp.opcode) | kResponseBit));
  w.u8(rsp.token);
  w.u8(static_cast<std::uint8_t>(rsp.status));
  w.u8(rsp.length);
  w.bytes(rsp.body());
  return finish(w, out, written);
}

Error decode_response(std::span<const std::uint8_t> in, Response& out) {
  ByteReader r(in);
  const std::uint8_t version = r.u8();
  const std::uint8_t opcode = r.u8();
  Response rsp{};
  rsp.token = r.u8();
  const std::uint8_t status = r.u8();
  rsp.length = r.u8();
  if (!r.ok()) return r.error();
  if (version != kProtocolVersion) return Error::bad_version;
  if ((opcode & kResponseBit) == 0) return Error::bad_type;
  if (rsp.length > kMaxResponsePayload) return Error::bad_length;
  r.bytes(std::span(rsp.payload).first(rsp.length));
  if (!r.ok()) return r.error();
  if (Error e = check_crc(in, r.position()); e != Error::ok) return e;
  rsp.status = static_cast<Status>(status);
  if (!is_known(rsp.status)) return Error::bad_value;
  rsp.opcode = static_cast<Opcode>(opcode & ~kResponseBit);
  out = rsp;
  return Error::ok;
}

}  // namespace tonus::proto
