// BVH reader: every kind of broken input is refused with the line it is on
// and a message naming what was expected and what was found.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include "bvh_samples.hpp"
#include "tonus/host/motion/bvh.hpp"

using namespace tonus::motion;
using tonus::test::kSmallBvh;

namespace {

// The small sample with its first `from` replaced by `to`.
std::string edit(const std::string& from, const std::string& to) {
  const std::string s = kSmallBvh;
  const std::size_t at = s.find(from);
  REQUIRE_MESSAGE(at != std::string::npos, from);
  return s.substr(0, at) + to + s.substr(at + from.size());
}

void check_error(const std::string& text, std::size_t line, const std::string& needle) {
  const ReadResult r = parse_bvh(text);
  REQUIRE_MESSAGE(!r.ok(), "accepted, expected an error containing: ", needle);
  CHECK_MESSAGE(r.error->line == line, r.error->message);
  CHECK_MESSAGE(r.error->message.find(needle) != std::string::npos, r.error->message, " lacks: ", needle);
  CHECK(r.clip.joints.empty());
  CHECK(r.clip.values.empty());
}

}  // namespace

TEST_CASE("errors: empty, truncated and misplaced sections") {
  check_error("", 1, "expected HIERARCHY, found end of file");
  check_error("  \n\n", 3, "expected HIERARCHY, found end of file");
  check_error("MOTION\n", 1, "expected HIERARCHY, found 'MOTION'");
  check_error("HIERARCHY\nJOINT a\n", 2, "expected ROOT, found 'JOINT'");
  const std::string small = kSmallBvh;
  check_error(small.substr(0, small.find("MOTION")), 16, "expected MOTION after the hierarchy, found end of file");
  check_error(small.substr(0, small.find("\t}\n}")), 14, "found end of file");
  check_error(small.substr(0, small.find("Frame Time")), 18, "expected 'Frame Time:', found end of file");
  check_error(small.substr(0, small.find("1 2 3")), 17, "'Frames: 3' but the file holds 0 frame lines");
  check_error(small.substr(0, small.find("7 8 9")), 19, "frame 0 has 6 values, expected 9");
}

TEST_CASE("errors: braces") {
  check_error(edit("\tJOINT Chest\n\t{\n", "\tJOINT Chest\n"), 7, "expected '{' after joint 'Chest', found 'OFFSET'");
  check_error(edit("End Site\n\t\t{\n", "End Site\n"), 11, "expected '{' after End Site, found 'OFFSET'");
  check_error(edit("\t}\n}\n", "\t}\n"), 15,
              "expected OFFSET, CHANNELS, JOINT, End Site or '}' in joint 'Hips', found 'MOTION'");
  check_error(edit("OFFSET 0 5 0", "OFFSET 0 5 0\nJOINT Finger"), 13, "an End Site cannot hold a JOINT");
  check_error(edit("End Site", "End Place"), 10, "expected 'Site' after 'End', found 'Place'");
  check_error(edit("End Site", "End Site Tip"), 10, "expected '{' after End Site, found 'Tip'");
  check_error(edit("ROOT Hips", "ROOT"), 2, "expected a joint name after ROOT, found end of line");
  check_error(edit("JOINT Chest", "JOINT {"), 6, "expected a joint name after JOINT, found '{'");
  check_error(edit("JOINT Chest", "JOINT Chest { {"), 6, "expected one '{' after joint 'Chest {', found two");
  check_error(edit("}\nMOTION", "}\n}\nMOTION"), 16, "expected MOTION after the hierarchy, found '}'");
}

TEST_CASE("errors: one ROOT only") {
  const std::string second_root = "ROOT Other\n{\n\tOFFSET 0 0 0\n\tCHANNELS 1 Xrotation\n}\nMOTION";
  check_error(edit("MOTION", second_root), 16, "a second ROOT");
}

TEST_CASE("errors: OFFSET") {
  check_error(edit("OFFSET 0 10 0", "OFFSET 0 10"), 8, "expected 3 numbers after OFFSET in joint 'Chest', found 2");
  check_error(edit("OFFSET 0 10 0", "OFFSET 0 10 0 4"), 8, "found 4");
  check_error(edit("OFFSET 0 10 0", "OFFSET 0 ten 0"), 8,
              "expected a finite number in the OFFSET of joint 'Chest', found 'ten'");
  check_error(edit("OFFSET 0 10 0", "OFFSET 0 nan 0"), 8, "found 'nan'");
  check_error(edit("OFFSET 0 5 0", "OFFSET 0 inf 0"), 12, "End Site 'Chest_End'");
  check_error(edit("\t\tOFFSET 0 10 0\n", ""), 9, "expected OFFSET in joint 'Chest' before End Site");
}

TEST_CASE("errors: CHANNELS") {
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Wrotation Yrotation"), 9,
              "unknown channel 'Wrotation'");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Xrotation"), 9,
              "CHANNELS 3 in joint 'Chest' lists 2 channel names");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 2 Zrotation Xrotation Yrotation"), 9,
              "CHANNELS 2 in joint 'Chest' lists 3 channel names");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Xrotation Zrotation"), 9,
              "channel Zrotation listed twice");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 7 Zrotation Xrotation Yrotation"), 9,
              "at most 6");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS -3 Zrotation Xrotation Yrotation"), 9,
              "expected a channel count after CHANNELS, found '-3'");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS"), 9, "found end of line");
  check_error(edit("\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n", ""), 9,
              "expected CHANNELS in joint 'Chest' before End Site");
  check_error(edit("OFFSET 0 5 0", "OFFSET 0 5 0\nCHANNELS 1 Xrotation"), 13, "an End Site cannot have channels");
  check_error(edit("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 0\nCHANNELS 0"), 10, "a second CHANNELS");
}

TEST_CASE("errors: the hierarchy has no channels, or too many joints") {
  check_error("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\n\n", 6,
              "the hierarchy has no channels");
  std::string deep = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  for (int i = 1; i <= 1024; ++i) deep += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n";
  check_error(deep, 2 + 4 * 1024, "more than 1024 joints");
  // 1024 entries are fine: a root and 1023 joints, one channel each.
  std::string wide = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  for (int i = 1; i < 1024; ++i) wide += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n}\n";
  wide += "}\nMOTION\nFrames: 1\nFrame Time: 0.01\n";
  for (int i = 0; i < 1024; ++i) wide += "0 ";
  const ReadResult r = parse_bvh(wide);
  REQUIRE_MESSAGE(r.ok(), r.error->message);
  CHECK(r.clip.joints.size() == 1024);
}

TEST_CASE("errors: frame lines") {
  check_error(edit("-1 -2 -3 -4 -5 -6 -7 -8 -9", "-1 -2 -3 -4 -5 -6 -7 -8"), 20, "frame 1 has 8 values, expected 9");
  check_error(edit("-1 -2 -3 -4 -5 -6 -7 -8 -9", "-1 -2 -3 -4 -5 -6 -7 -8 -9 -10"), 20,
              "frame 1 has 10 values, expected 9");
  check_error(edit("-1 -2 -3", "-1 -2x -3"), 20, "expected a number in frame 1, found '-2x'");
  check_error(edit("-1 -2 -3", "-1 - -3"), 20, "found '-'");
  check_error(edit("-1 -2 -3", "-1 1,5 -3"), 20, "found '1,5'");
  check_error(edit("-1 -2 -3", "-1 nan -3"), 20, "expected a finite number in frame 1, found 'nan'");
  check_error(edit("-1 -2 -3", "-1 -inf -3"), 20, "finite number");
  check_error(edit("-1 -2 -3", "-1 1e999 -3"), 20, "finite number");
  check_error(edit("-1 -2 -3", "-1 0x10 -3"), 20, "found '0x10'");
  check_error(edit("-1 -2 -3", "-1 \x01 -3"), 20, "found '\\x01'");
}

TEST_CASE("errors: Frames: count against the frame lines present, and zero frames") {
  check_error(edit("Frames: 3", "Frames: 4"), 17, "'Frames: 4' but the file holds 3 frame lines");
  check_error(edit("Frames: 3", "Frames: 2"), 17, "'Frames: 2' but the file holds 3 frame lines");
  check_error(edit("Frames: 3", "Frames: 99999999999"), 17, "'Frames: 99999999999' but the file holds 3");
  check_error(edit("Frames: 3", "Frames: 0"), 17, "no motion");
  check_error(edit("Frames: 3", "Frames: -3"), 17, "expected a frame count after 'Frames:', found '-3'");
  check_error(edit("Frames: 3", "Frames: 3.0"), 17, "found '3.0'");
  check_error(edit("Frames: 3", "Frames: 99999999999999999999999"), 17, "expected a frame count");
  check_error(edit("Frames: 3", "Frame: 3"), 17, "expected 'Frames:', found 'Frame:'");
  check_error(edit("Frame Time:", "FrameTime:"), 18, "expected 'Frame Time:', found 'FrameTime:'");
  check_error(edit("Frame Time: 0.0333333", "Frame Time: 0.0333333 s"), 18,
              "expected the end of the line after the frame time, found 's'");
}

TEST_CASE("errors: the frame time must be a finite positive number") {
  for (const char* bad : {"0", "-0.0333", "nan", "inf", "1e999", "abc", "0.0"}) {
    check_error(edit("0.0333333", bad), 18, "expected a positive frame time in seconds");
  }
}

TEST_CASE("errors: files that cannot be read come back with line 0") {
  const ReadResult missing = read_bvh_file("/nonexistent/motion.bvh");
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.error->line == 0);
  CHECK(missing.error->message.find("/nonexistent/motion.bvh") != std::string::npos);
  const ReadResult folder = read_bvh_file(std::filesystem::temp_directory_path().string());
  REQUIRE_FALSE(folder.ok());
  CHECK(folder.error->line == 0);
}
