#include "tonus/protocol/hid.hpp"

namespace tonus::proto::hid {

namespace {

template <class Message, class Encode>
Error pack(std::uint8_t id, const Message& msg, Report& out, Encode encode) {
  out.fill(0);
  out[0] = id;
  std::size_t written = 0;
  return encode(msg, std::span(out).subspan(1), written);
}

template <class Message, class Decode>
Error unpack(std::uint8_t id, std::span<const std::uint8_t> report, Message& out, Decode decode) {
  if (report.empty()) return Error::truncated;
  if (report.size() > kReportSize) return Error::bad_length;
  if (report[0] != id) return Error::bad_type;
  return decode(report.subspan(1), out);
}

}  // namespace

Error pack_stream(const StreamMessage& msg, Report& out) { return pack(kReportIdStream, msg, out, encode_stream); }
Error pack_request(const Request& req, Report& out) { return pack(kReportIdCommand, req, out, encode_request); }
Error pack_response(const Response& rsp, Report& out) { return pack(kReportIdResponse, rsp, out, encode_response); }

Error unpack_stream(std::span<const std::uint8_t> report, StreamMessage& out) {
  return unpack(kReportIdStream, report, out, decode_stream);
}
Error unpack_request(std::span<const std::uint8_t> report, Request& out) {
  return unpack(kReportIdCommand, report, out, decode_request);
}
Error unpack_response(std::span<const std::uint8_t> report, Response& out) {
  return unpack(kReportIdResponse, report, out, decode_response);
}

}  // namespace tonus::proto::hid
