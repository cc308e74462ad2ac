// BVH writer: the standard layout, and read -> write -> read round trips
// exact to the written precision, on synthetic clips and every shared clip.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "bvh_samples.hpp"
#include "tonus/host/motion/bvh.hpp"

using namespace tonus::motion;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void check_same_hierarchy(const Clip& a, const Clip& b) {
  REQUIRE(a.joints.size() == b.joints.size());
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    CHECK(a.joints[j].name == b.joints[j].name);
    CHECK(a.joints[j].parent == b.joints[j].parent);
    CHECK(a.joints[j].offset == b.joints[j].offset);  // shortest form reads back bit for bit
    CHECK(a.joints[j].channels == b.joints[j].channels);
    CHECK(a.joints[j].end_site == b.joints[j].end_site);
  }
  CHECK(a.frame_time_s == b.frame_time_s);
  CHECK(a.frame_count == b.frame_count);
}

// write -> read keeps every value to half a unit of the last written digit,
// and writing what was read gives the same text again.
void check_round_trip(const Clip& clip, int decimals) {
  const std::string text = write_bvh(clip, decimals);
  REQUIRE_FALSE(text.empty());
  const ReadResult back = parse_bvh(text);
  REQUIRE_MESSAGE(back.ok(), back.error->line, ": ", back.error->message);
  check_same_hierarchy(clip, back.clip);
  REQUIRE(back.clip.values.size() == clip.values.size());
  const double half_unit = 0.5 * std::pow(10.0, -decimals);
  double worst = 0.0;
  for (std::size_t i = 0; i < clip.values.size(); ++i) {
    const double err = std::abs(back.clip.values[i] - clip.values[i]);
    // Decimal rounding plus the double nearest the written decimal.
    worst = std::max(worst, err - (half_unit + 4e-16 * std::abs(clip.values[i])));
  }
  CHECK(worst <= 0.0);
  CHECK(write_bvh(back.clip, decimals) == text);
}

}  // namespace

TEST_CASE("writer: the standard layout, tab indentation and LF endings") {
  const ReadResult r = parse_bvh(tonus::test::kSmallBvh);
  REQUIRE(r.ok());
  const std::string expected =
      "HIERARCHY\n"
      "ROOT Hips\n"
      "{\n"
      "\tOFFSET 0.5 1.5 -2.5\n"
      "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
      "\tJOINT Chest\n"
      "\t{\n"
      "\t\tOFFSET 0 10 0\n"
      "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
      "\t\tEnd Site\n"
      "\t\t{\n"
      "\t\t\tOFFSET 0 5 0\n"
      "\t\t}\n"
      "\t}\n"
      "}\n"
      "MOTION\n"
      "Frames: 3\n"
      "Frame Time: 0.0333333\n"
      "1.00 2.00 3.00 4.00 5.00 6.00 7.00 8.00 9.00\n"
      "-1.00 -2.00 -3.00 -4.00 -5.00 -6.00 -7.00 -8.00 -9.00\n"
      "0.50 0.25 -0.00 10.00 0.00 0.00 0.00 0.00 90.00\n";
  CHECK(write_bvh(r.clip, 2) == expected);
}

TEST_CASE("writer: siblings close their subtrees, End Sites anywhere, names with blanks") {
  const char* text =
      "HIERARCHY\nROOT Bip01\n{\n\tOFFSET 0 0 0\n\tCHANNELS 3 Xposition Yposition Zposition\n"
      "\tJOINT Bip01 L Thigh\n\t{\n\t\tOFFSET 1 0 0\n\t\tCHANNELS 1 Zrotation\n"
      "\t\tJOINT Bip01 L Calf\n\t\t{\n\t\t\tOFFSET 0 -4 0\n\t\t\tCHANNELS 0\n\t\t}\n\t}\n"
      "\tEnd Site\n\t{\n\t\tOFFSET 0 1e-07 0\n\t}\n"
      "\tJOINT Bip01 R Thigh\n\t{\n\t\tOFFSET -1 0 0\n\t\tCHANNELS 1 Zrotation\n\t}\n}\n"
      "MOTION\nFrames: 2\nFrame Time: 0.0083333\n1 2 3 4 5\n-1 -2 -3 -4 -5\n";
  const ReadResult r = parse_bvh(text);
  REQUIRE_MESSAGE(r.ok(), r.error->message);
  // Written with 0 decimals it is this very text with integer values.
  CHECK(write_bvh(r.clip, 0) == text);
  check_round_trip(r.clip, 6);
}

TEST_CASE("writer: synthetic clips round trip at every precision") {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Clip clip = tonus::test::synthetic_clip(50, seed);
    REQUIRE_FALSE(check_clip(clip).has_value());
    for (const int decimals : {0, 1, 3, 6, 9, 12, 17}) {
      CAPTURE(decimals);
      check_round_trip(clip, decimals);
    }
  }
}

TEST_CASE("writer: decimals are clamped to 0..17") {
  const Clip clip = tonus::test::synthetic_clip(2, 9);
  CHECK(write_bvh(clip, -4) == write_bvh(clip, 0));
  CHECK(write_bvh(clip, 40) == write_bvh(clip, 17));
}

TEST_CASE("writer: extreme finite values and the frame time keep their exact value") {
  Clip clip = tonus::test::synthetic_clip(1, 3);
  clip.values[0] = 1.7976931348623157e308;
  clip.values[1] = -4.9e-324;
  clip.values[2] = 123456789012.125;
  clip.joints[0].offset = {1e-300, -1e300, 0.1};
  clip.frame_time_s = 1.0 / 60.0;
  const ReadResult back = parse_bvh(write_bvh(clip, 3));
  REQUIRE_MESSAGE(back.ok(), back.error->message);
  CHECK(back.clip.values[0] == clip.values[0]);
  CHECK(back.clip.values[1] == 0.0);
  CHECK(back.clip.values[2] == 123456789012.125);
  CHECK(back.clip.joints[0].offset == clip.joints[0].offset);
  CHECK(back.clip.frame_time_s == 1.0 / 60.0);
}

TEST_CASE("writer: an invalid clip gives an empty string") {
  const Clip good = tonus::test::synthetic_clip(3, 4);
  REQUIRE_FALSE(write_bvh(good).empty());
  auto broken = [&good](auto&& change) {
    Clip c = good;
    change(c);
    CHECK(check_clip(c).has_value());
    return write_bvh(c);
  };
  CHECK(broken([](Clip& c) { c.joints.clear(); }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].parent = 2; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].parent = -1; }).empty());
  CHECK(broken([](Clip& c) { c.joints[0].end_site = true; }).empty());
  CHECK(broken([](Clip& c) { c.joints[2].channels = {Channel::x_rotation}; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].channels.push_back(Channel::x_rotation); }).empty());
  CHECK(broken([](Clip& c) { c.joints[0].channels.push_back(Channel::x_rotation); }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].offset.x() = kNaN; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].name = ""; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].name = "Arm\nJOINT x"; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].name = " Arm"; }).empty());
  CHECK(broken([](Clip& c) { c.joints[1].name = "Arm {"; }).empty());
  CHECK(broken([](Clip& c) { c.frame_time_s = 0.0; }).empty());
  CHECK(broken([](Clip& c) { c.frame_time_s = kInf; }).empty());
  CHECK(broken([](Clip& c) {
          c.frame_count = 0;
          c.values.clear();
        }).empty());
  CHECK(broken([](Clip& c) { c.values.pop_back(); }).empty());
  CHECK(broken([](Clip& c) { c.values[5] = kNaN; }).empty());
  CHECK(broken([](Clip& c) {
          c.joints[0].channels.clear();
          c.joints[1].channels.clear();
          c.values.clear();
        }).empty());
  // Not in depth-first order: Root, A (of Root), B (of Root), A's child.
  CHECK(broken([](Clip& c) {
          c.joints.insert(c.joints.begin() + 2,
                          Joint{.name = "B", .parent = 0, .offset = {}, .channels = {}, .end_site = false});
          c.joints[3].parent = 1;
        }).empty());
}

TEST_CASE("writer: every shared clip round trips at 6 decimals (and at 4, the CMU files' own precision)") {
  for (const char* name : tonus::test::kSharedClips) {
    CAPTURE(name);
    const ReadResult r = read_bvh_file(tonus::test::shared_bvh(name));
    REQUIRE_MESSAGE(r.ok(), r.error->message);
    check_round_trip(r.clip, 6);
    if (std::string(name).starts_with("cmu_")) {
      // Every CMU value has at most 4 decimals: writing 4 loses nothing.
      const ReadResult again = parse_bvh(write_bvh(r.clip, 4));
      REQUIRE(again.ok());
      CHECK(again.clip.values == r.clip.values);
    }
  }
}
