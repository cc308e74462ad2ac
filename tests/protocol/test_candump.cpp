#include <doctest/doctest.h>

#include <unistd.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tonus/protocol/candump.hpp"

using namespace tonus::proto;
using namespace tonus::proto::candump;

namespace {

std::string format_line(const Record& rec) {
  std::array<char, kMaxLine> buf{};
  std::size_t n = 0;
  REQUIRE(format(rec, buf, n) == Error::ok);
  return {buf.data(), n};
}

Record make_record(std::uint64_t t, const char* iface, std::uint32_t id, std::initializer_list<std::uint8_t> data) {
  Record r{};
  r.time_us = t;
  REQUIRE(set_iface(r, iface));
  r.frame.id = id;
  r.frame.dlc = static_cast<std::uint8_t>(data.size());
  std::size_t i = 0;
  for (std::uint8_t b : data) r.frame.data[i++] = b;
  return r;
}

}  // namespace

TEST_CASE("candump lines are formatted as can-utils writes them") {
  CHECK(format_line(make_record(1436509052249713ULL, "vcan0", 0x044, {0x2A, 0x36, 0x6C, 0x2B, 0xBA})) ==
        "(1436509052.249713) vcan0 044#2A366C2BBA\n");
  CHECK(format_line(make_record(5, "can0", 0x7FF, {})) == "(0000000000.000005) can0 7FF#\n");
  Record ext = make_record(1000000, "can1", 0x1ABCDEF0, {0x01});
  ext.frame.flags = CanFrame::kExtended;
  CHECK(format_line(ext) == "(0000000001.000000) can1 1ABCDEF0#01\n");
  Record rtr = make_record(0, "can0", 0x123, {});
  rtr.frame.flags = CanFrame::kRemote;
  rtr.frame.dlc = 4;
  CHECK(format_line(rtr) == "(0000000000.000000) can0 123#R4\n");
}

TEST_CASE("candump lines round-trip, including remote, extended and error frames") {
  Record recs[4] = {make_record(1700000000123456ULL, "vcan0", 0x101, {1, 2, 3, 4, 5, 6, 7, 8}),
                    make_record(1, "can0", 0x000, {}), make_record(2, "x", 0x1FFFFFFF, {0xFF}),
                    make_record(3, "can0", 0x0080, {0, 0, 0, 0, 0, 0, 0, 0})};
  recs[2].frame.flags = CanFrame::kExtended;
  recs[3].frame.flags = CanFrame::kExtended | CanFrame::kErrorFrame;
  for (const Record& r : recs) {
    Record back{};
    REQUIRE(parse(format_line(r), back) == Error::ok);
    CHECK(back == r);
  }
}

TEST_CASE("candump parser accepts what can-utils writes") {
  Record r{};
  REQUIRE(parse("(1436509052.249713) vcan0 044#2a366c2bba\r\n", r) == Error::ok);
  CHECK(r.time_us == 1436509052249713ULL);
  CHECK(r.iface_name() == "vcan0");
  CHECK(r.frame.id == 0x044);
  CHECK(r.frame.dlc == 5);
  CHECK(r.frame.data[4] == 0xBA);
  REQUIRE(parse("(0.000001) can0 123#R", r) == Error::ok);
  CHECK((r.frame.flags & CanFrame::kRemote) != 0);
  CHECK(r.frame.dlc == 0);
  REQUIRE(parse("(1.000000) can0 20000080#0000000000000000", r) == Error::ok);
  CHECK((r.frame.flags & CanFrame::kErrorFrame) != 0);
  CHECK(r.frame.id == 0x80);
}

TEST_CASE("candump parser rejects malformed lines") {
  const char* bad[] = {
      "",
      "1436509052.249713 vcan0 044#00",                    // no parentheses
      "(1436509052.24971) vcan0 044#00",                   // 5-digit micros
      "(1436509052.249713)vcan0 044#00",                   // missing space
      "(1436509052.249713) vcan0",                         // no frame
      "(1436509052.249713) vcan0 044",                     // no '#'
      "(1436509052.249713) vcan0 44#00",                   // 2-digit id
      "(1436509052.249713) vcan0 800#00",                  // over 11 bits
      "(1436509052.249713) vcan0 G44#00",                  // not hex
      "(1436509052.249713) vcan0 044#0",                   // odd data length
      "(1436509052.249713) vcan0 044#000102030405060708",  // 9 bytes
      "(1436509052.249713) vcan0 044#R9",                  // remote dlc over 8
      "(1436509052.249713) averyveryverylongname 044#00",  // iface over 15
      "(9999999999999.000000) vcan0 044#00",               // seconds overflow guard
  };
  for (const char* line : bad) {
    CAPTURE(line);
    Record r{};
    CHECK(parse(line, r) != Error::ok);
  }
  Record r{};
  CHECK(parse("(1.000000) can0 123##1DEADBEEF", r) == Error::bad_type);  // CAN FD
}

TEST_CASE("can-utils log2asc reads a log we wrote") {
  char path[] = "/tmp/tonus_candump_XXXXXX";
  const int fd = mkstemp(path);
  REQUIRE(fd >= 0);
  close(fd);
  {
    std::ofstream out(path);
    out << format_line(make_record(1700000000000000ULL, "can0", 0x101, {0x34, 0x12, 0x78, 0x56, 0, 0, 1, 0}));
    out << format_line(make_record(1700000000000150ULL, "can0", 0x121, {0xAA, 0xBB}));
  }
  const std::string cmd = std::string(TONUS_LOG2ASC) + " -I " + path + " can0 2>&1";
  std::FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string output;
  std::array<char, 512> chunk{};
  std::size_t n = 0;
  while ((n = std::fread(chunk.data(), 1, chunk.size(), pipe)) > 0) output.append(chunk.data(), n);
  const int status = pclose(pipe);
  std::remove(path);
  INFO(output);
  CHECK(status == 0);
  // log2asc prints "<time> <channel> <id> Rx d <dlc> <bytes>" per frame.
  CHECK(output.find("101") != std::string::npos);
  CHECK(output.find("34 12 78 56 00 00 01 00") != std::string::npos);
  CHECK(output.find("121") != std::string::npos);
  CHECK(output.find("AA BB") != std::string::npos);
  CHECK(output.find("0.000150") != std::string::npos);  // relative time of the second frame
}

TEST_CASE("candump parser: every truncation and single-character corruption is an error or a consistent record") {
  const std::string line =
      format_line(make_record(1700000000123456ULL, "can0", 0x1E1, {0x04, 0x00, 0x80, 0x00, 0x00, 0x00, 0x37, 0x34}));
  // The format has no length field: a line cut inside the data at a byte
  // boundary is a valid shorter frame. Any other cut is an error.
  const std::size_t data_start = line.find('#') + 1;
  for (std::size_t len = 0; len < line.size() - 1; ++len) {
    Record r{};
    CAPTURE(len);
    const Error e = parse(std::string_view(line).substr(0, len), r);
    if (len >= data_start && (len - data_start) % 2 == 0) {
      REQUIRE(e == Error::ok);
      CHECK(r.frame.dlc == (len - data_start) / 2);
      CHECK(r.frame.id == 0x1E1);
    } else {
      CHECK(e != Error::ok);
    }
  }
  std::size_t accepted = 0;
  std::string copy = line;
  for (std::size_t i = 0; i + 1 < copy.size(); ++i) {  // the newline stays
    const char original = copy[i];
    for (int c = 0; c < 256; ++c) {
      if (static_cast<char>(c) == original) continue;
      copy[i] = static_cast<char>(c);
      Record r{};
      if (parse(copy, r) == Error::ok) {
        // Whatever was accepted must format back to a line that parses to the same record.
        ++accepted;
        Record again{};
        REQUIRE(parse(format_line(r), again) == Error::ok);
        CHECK(again == r);
      }
    }
    copy[i] = original;
  }
  // Hex digits of the id and data may change into other hex digits: those are valid frames.
  CHECK(accepted > 0);
}
