// Links every protocol entry point into a binary whose malloc/new/throw are
// poisoned with --wrap (see tonus_poison_heap): if any of them allocated or
// threw, this would not link. Running it also checks one round trip of each.
#include <array>
#include <cstdio>
#include <string_view>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/candump.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/hid_descriptor.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/sequence.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus::proto;

namespace {

int failures = 0;

void expect(bool ok, const char* what) {
  if (!ok) {
    std::printf("FAIL: %s\n", what);
    ++failures;
  }
}

}  // namespace

int main() {
  StreamMessage msg{};
  msg.sequence = 0xFFFF;
  msg.levels[0] = 1234;
  hid::Report report{};
  StreamMessage back{};
  expect(hid::pack_stream(msg, report) == Error::ok && hid::unpack_stream(report, back) == Error::ok && back == msg,
         "hid stream");

  std::array<CanFrame, can::kMaxStreamFrames> frames{};
  std::size_t count = 0;
  can::StreamAssembler assembler(3);
  bool complete = false;
  expect(can::encode_stream(msg, 3, true, frames, count) == Error::ok, "can encode");
  for (std::size_t i = 0; i < count; ++i) assembler.push(frames[i], complete);
  expect(complete && assembler.message() == msg, "can stream");

  Request req{};
  Response rsp{};
  Request req_back{};
  Response rsp_back{};
  DeviceConfig cfg{};
  expect(make_request(Opcode::set_config, 9, cfg, req) == Error::ok, "make request");
  expect(check_config(cfg, 4) == ConfigField::none, "default config valid");
  expect(hid::pack_request(req, report) == Error::ok && hid::unpack_request(report, req_back) == Error::ok &&
             req_back == req,
         "hid request");
  expect(make_response(req, Status::ok, TimeSyncResponse{1, 2, 3}, rsp) == Error::ok, "make response");
  std::array<std::uint8_t, kMaxMessageSize> bytes{};
  std::size_t n = 0;
  expect(encode_response(rsp, bytes, n) == Error::ok, "encode response");
  std::array<CanFrame, can::kMaxSegments> segs{};
  expect(can::segment(std::span(bytes).first(n), can::Function::response, 3, segs, count) == Error::ok, "segment");
  can::Reassembler reasm(can::Function::response, 3);
  for (std::size_t i = 0; i < count; ++i) reasm.push(segs[i], complete);
  expect(complete && decode_response(reasm.message(), rsp_back) == Error::ok && rsp_back == rsp, "can response");
  TimeSyncResponse ts{};
  expect(read_payload(rsp_back, ts) == Error::ok && ts.device_tx_us == 3, "typed payload");

  hid::DescriptorInfo info{};
  expect(hid::parse_report_descriptor(hid::kReportDescriptor, info) == Error::ok, "descriptor");

  candump::Record rec{};
  candump::set_iface(rec, "can0");
  rec.frame = frames[0];
  std::array<char, candump::kMaxLine> line{};
  candump::Record rec_back{};
  expect(candump::format(rec, line, n) == Error::ok &&
             candump::parse(std::string_view(line.data(), n), rec_back) == Error::ok && rec_back == rec,
         "candump");

  SequenceTracker seq;
  seq.push(65535);
  seq.push(1);
  expect(seq.lost() == 1, "sequence wrap");

  std::printf("protocol_noalloc: %s\n", failures == 0 ? "ok" : "FAILED");
  return failures == 0 ? 0 : 1;
}
