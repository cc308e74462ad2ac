#include <doctest/doctest.h>

#include <array>
#include <random>
#include <vector>

#include "support/mutate.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/hid_descriptor.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus::proto;
using namespace tonus::proto::hid;

TEST_CASE("the report descriptor declares exactly the reports the codec sends") {
  DescriptorInfo info{};
  REQUIRE(parse_report_descriptor(kReportDescriptor, info) == Error::ok);
  CHECK(info.usage_page == kUsagePage);
  CHECK(info.usage == 0x01);
  CHECK(info.uses_report_ids);
  CHECK(info.report_count == 3);
  CHECK(info.report_bytes(kReportIdStream, ReportType::input) == kReportSize);
  CHECK(info.report_bytes(kReportIdCommand, ReportType::output) == kReportSize);
  CHECK(info.report_bytes(kReportIdResponse, ReportType::input) == kReportSize);
  CHECK(info.report_bytes(kReportIdCommand, ReportType::input) == 0);
  CHECK(info.report_bytes(kReportIdStream, ReportType::feature) == 0);
  // The largest message of each kind fits its report payload.
  CHECK(stream_message_size(kMaxGroups, kMaxChannels) <= kReportPayload);
  CHECK(kRequestOverhead + kMaxRequestPayload <= kReportPayload);
  CHECK(kResponseOverhead + kMaxResponsePayload <= kReportPayload);
}

TEST_CASE("descriptor parser totals bits per report and handles push/pop and long items") {
  // Two reports: id 5 input = 3 x 8 + 1 x 16 bits; feature id 6 = 2 x 4 bits (rounded up to 1 byte).
  const std::vector<std::uint8_t> desc = {
      0x05, 0x01, 0x09, 0x02, 0xA1, 0x01,              // Usage Page (1), Usage (2), Collection (Application)
      0x85, 0x05, 0x75, 0x08, 0x95, 0x03, 0x81, 0x02,  // id 5: 3 x 8 input
      0xA4,                                            // Push
      0x75, 0x10, 0x95, 0x01, 0x81, 0x02,              // 1 x 16 input
      0xB4,                                            // Pop: back to size 8, count 3
      0xFE, 0x02, 0x10, 0xAA, 0xBB,                    // long item, skipped
      0x85, 0x06, 0x75, 0x04, 0x95, 0x02, 0xB1, 0x02,  // id 6: 2 x 4 feature
      0xC0};
  DescriptorInfo info{};
  REQUIRE(parse_report_descriptor(desc, info) == Error::ok);
  CHECK(info.usage_page == 0x0001);
  CHECK(info.usage == 0x0002);
  CHECK(info.report_bytes(5, ReportType::input) == 1 + 5);
  CHECK(info.report_bytes(6, ReportType::feature) == 1 + 1);
}

TEST_CASE("descriptor parser rejects malformed descriptors") {
  const std::vector<std::vector<std::uint8_t>> bad = {
      {0x06, 0x00},                                      // truncated item data
      {0xA1, 0x01},                                      // unclosed collection
      {0xC0},                                            // end without collection
      {0xA1, 0x01, 0xB4, 0xC0},                          // pop without push
      {0xA1, 0x01, 0x85, 0x00, 0xC0},                    // report id 0 is reserved
      {0x81, 0x02},                                      // input outside a collection
      {0xA1, 0x01, 0x0C, 0xC0},                          // reserved item type
      {0xFE, 0x05, 0x00, 0x01},                          // long item longer than the data
      {0xA1, 0x01, 0x77, 0xFF, 0xFF, 0xFF, 0xFF,         // report size 2^32-1 ...
       0x97, 0xFF, 0xFF, 0xFF, 0xFF, 0x81, 0x02, 0xC0},  // ... times count 2^32-1
  };
  for (const auto& d : bad) {
    DescriptorInfo info{};
    CHECK(parse_report_descriptor(d, info) != Error::ok);
  }
}

TEST_CASE("descriptor parser survives every truncation and single-byte corruption") {
  for (std::size_t len = 0; len < kReportDescriptor.size(); ++len) {
    DescriptorInfo info{};
    CHECK(parse_report_descriptor(std::span(kReportDescriptor).first(len), info) != Error::ok);
  }
  std::size_t ok = 0;
  tonus::test::for_each_byte_corruption(kReportDescriptor, [&](std::span<const std::uint8_t> bytes) {
    DescriptorInfo info{};
    if (parse_report_descriptor(bytes, info) == Error::ok) ++ok;
    CHECK(info.report_count <= DescriptorInfo::kMaxReports);
  });
  CHECK(ok > 0);  // e.g. other usage values still parse
}

TEST_CASE("HID reports carry each message kind with its id and zero padding") {
  StreamMessage msg{};
  msg.sequence = 77;
  msg.levels[1] = 40000;
  Report report{};
  report.fill(0xEE);
  REQUIRE(pack_stream(msg, report) == Error::ok);
  CHECK(report[0] == kReportIdStream);
  for (std::size_t i = 1 + stream_message_size(4, 8); i < kReportSize; ++i) CHECK(report[i] == 0);
  StreamMessage back{};
  REQUIRE(unpack_stream(report, back) == Error::ok);
  CHECK(back == msg);

  Request req{};
  REQUIRE(make_request(Opcode::time_sync, 4, TimeSyncRequest{99}, req) == Error::ok);
  REQUIRE(pack_request(req, report) == Error::ok);
  CHECK(report[0] == kReportIdCommand);
  Request rb{};
  REQUIRE(unpack_request(report, rb) == Error::ok);
  CHECK(rb == req);

  Response rsp = make_response(req, Status::busy);
  REQUIRE(pack_response(rsp, report) == Error::ok);
  CHECK(report[0] == kReportIdResponse);
  Response sb{};
  REQUIRE(unpack_response(report, sb) == Error::ok);
  CHECK(sb == rsp);
  CHECK(unpack_stream(report, back) == Error::bad_type);  // a response is not a stream report
}

TEST_CASE("HID unpack: empty, over-long and short reports") {
  StreamMessage msg{};
  Report report{};
  REQUIRE(pack_stream(msg, report) == Error::ok);
  StreamMessage back{};
  CHECK(unpack_stream({}, back) == Error::truncated);
  std::array<std::uint8_t, kReportSize + 1> longer{};
  longer[0] = kReportIdStream;
  CHECK(unpack_stream(longer, back) == Error::bad_length);
  // An OS that strips trailing padding still delivers a decodable report.
  CHECK(unpack_stream(std::span(report).first(1 + stream_message_size(4, 8)), back) == Error::ok);
  CHECK(unpack_stream(std::span(report).first(stream_message_size(4, 8)), back) == Error::truncated);
}
