// BVH reader: what it reads from a known small file, and the formatting
// variants real exporters produce, each giving the same clip.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "bvh_samples.hpp"
#include "tonus/host/motion/bvh.hpp"

using namespace tonus::motion;
using tonus::test::kSmallBvh;

namespace {

std::string replace_all(const std::string& s, const std::string& from, const std::string& to) {
  std::string out;
  std::size_t start = 0;
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, start)) {
    out.append(s, start, at - start);
    out += to;
    start = at + from.size();
  }
  out.append(s, start);
  return out;
}

// Same hierarchy, frame time and values (bit for bit) as the small sample.
void check_same_as_small(const ReadResult& r) {
  REQUIRE_MESSAGE(r.ok(), r.error->line, ": ", r.error->message);
  const ReadResult ref = parse_bvh(kSmallBvh);
  REQUIRE(ref.ok());
  REQUIRE(r.clip.joints.size() == ref.clip.joints.size());
  for (std::size_t j = 0; j < ref.clip.joints.size(); ++j) {
    CHECK(r.clip.joints[j].name == ref.clip.joints[j].name);
    CHECK(r.clip.joints[j].parent == ref.clip.joints[j].parent);
    CHECK(r.clip.joints[j].offset == ref.clip.joints[j].offset);
    CHECK(r.clip.joints[j].channels == ref.clip.joints[j].channels);
    CHECK(r.clip.joints[j].end_site == ref.clip.joints[j].end_site);
  }
  CHECK(r.clip.frame_time_s == ref.clip.frame_time_s);
  CHECK(r.clip.frame_count == ref.clip.frame_count);
  CHECK(r.clip.values == ref.clip.values);
}

}  // namespace

TEST_CASE("reader: the small sample's hierarchy, frame time and values") {
  const ReadResult r = parse_bvh(kSmallBvh);
  REQUIRE(r.ok());
  CHECK(r.warnings.empty());
  const Clip& c = r.clip;
  REQUIRE(c.joints.size() == 3);
  CHECK(c.joints[0].name == "Hips");
  CHECK(c.joints[0].parent == -1);
  CHECK(c.joints[0].offset == Eigen::Vector3d(0.5, 1.5, -2.5));
  CHECK(c.joints[0].channels == std::vector<Channel>{Channel::x_position, Channel::y_position, Channel::z_position,
                                                     Channel::z_rotation, Channel::y_rotation, Channel::x_rotation});
  CHECK_FALSE(c.joints[0].end_site);
  CHECK(c.joints[1].name == "Chest");
  CHECK(c.joints[1].parent == 0);
  CHECK(c.joints[1].offset == Eigen::Vector3d(0, 10, 0));
  CHECK(c.joints[1].channels == std::vector<Channel>{Channel::z_rotation, Channel::x_rotation, Channel::y_rotation});
  CHECK(c.joints[2].name == "Chest_End");
  CHECK(c.joints[2].parent == 1);
  CHECK(c.joints[2].end_site);
  CHECK(c.joints[2].channels.empty());
  CHECK(c.joints[2].offset == Eigen::Vector3d(0, 5, 0));
  CHECK(c.frame_time_s == 0.0333333);
  CHECK(c.frame_count == 3);
  CHECK(c.channel_count() == 9);
  REQUIRE(c.values.size() == 27);
  CHECK(c.values[0] == 1.0);
  CHECK(c.values[8] == 9.0);
  CHECK(c.values[9] == -1.0);
  CHECK(c.values[18] == 0.5);
  CHECK(c.values[19] == 0.25);  // ".25"
  CHECK(c.values[20] == 0.0);
  CHECK(std::signbit(c.values[20]));  // "-0.00000" keeps its sign
  CHECK(c.values[21] == 10.0);        // "1e1"
  CHECK(c.values[22] == 7.7e-06);
  CHECK(c.values[26] == 90.0);
  CHECK(c.frame(1).size() == 9);
  CHECK(c.frame(1)[0] == -1.0);
  CHECK(c.frame(3).empty());
  CHECK(channel_columns(c) == std::vector<std::size_t>{0, 6, 9, 9});
  CHECK(find_joint(c, "Chest") == std::optional<std::size_t>(1));
  CHECK(find_joint(c, "Chest_End") == std::optional<std::size_t>(2));
  CHECK_FALSE(find_joint(c, "chest").has_value());
  CHECK_FALSE(check_clip(c).has_value());
}

TEST_CASE("reader: line endings CRLF, CR, mixed, and no final line break") {
  const std::string lf = kSmallBvh;
  check_same_as_small(parse_bvh(replace_all(lf, "\n", "\r\n")));
  check_same_as_small(parse_bvh(replace_all(lf, "\n", "\r")));
  std::string mixed;  // every other line ends in CRLF
  for (std::size_t n = 0; const char c : lf) {
    if (c == '\n' && n++ % 2 == 0) mixed += '\r';
    mixed += c;
  }
  check_same_as_small(parse_bvh(mixed));
  check_same_as_small(parse_bvh(lf.substr(0, lf.size() - 1)));
  check_same_as_small(parse_bvh(lf + "\n\n  \t\n"));
}

TEST_CASE("reader: blanks of any kind, a byte order mark, letter case of keywords") {
  const std::string lf = kSmallBvh;
  check_same_as_small(parse_bvh(replace_all(lf, "\t", "    ")));
  check_same_as_small(parse_bvh(replace_all(replace_all(lf, " ", " \t "), "\n", " \t\n")));
  check_same_as_small(parse_bvh("\xEF\xBB\xBF" + lf));
  check_same_as_small(parse_bvh(replace_all(lf, "End Site", "End site")));
  check_same_as_small(parse_bvh(replace_all(lf, "End Site", "END SITE")));
  std::string lower = replace_all(replace_all(lf, "HIERARCHY", "hierarchy"), "MOTION", "Motion");
  lower = replace_all(replace_all(lower, "Zrotation", "ZROTATION"), "Xposition", "XPosition");
  check_same_as_small(parse_bvh(lower));
  check_same_as_small(parse_bvh(replace_all(lf, "Frames: 3", "Frames:\t3")));
  check_same_as_small(parse_bvh(replace_all(lf, "Frame Time: ", "Frame Time:\t")));
  check_same_as_small(parse_bvh(replace_all(lf, "Frame Time: 0.0333333", "Frame Time:   .0333333")));
  check_same_as_small(parse_bvh(replace_all(lf, "Frames: 3\n", "Frames:\n3\n")));
}

TEST_CASE("reader: braces on the keyword's line, blank lines among frames, '+' signs") {
  const std::string lf = kSmallBvh;
  check_same_as_small(
      parse_bvh(replace_all(replace_all(lf, "Chest\n\t{", "Chest {"), "End Site\n\t\t{", "End Site {")));
  check_same_as_small(parse_bvh(replace_all(lf, "5 6 7 8 9\n-1", "5 6 7 8 9\n\n \t\n-1")));
  check_same_as_small(parse_bvh(replace_all(lf, "1 2 3 4 5 6 7 8 9", "+1 2 3 4 5 6 7 8 9.0")));
  check_same_as_small(parse_bvh(replace_all(lf, "1e1", "1.0E+1")));
}

TEST_CASE("reader: joint names with blanks, several End Sites, joints without End Site or channels") {
  const char* text =
      "HIERARCHY\nROOT Bip01\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n"
      " JOINT Bip01 L Thigh\n {\n  OFFSET 1 0 0\n  CHANNELS 0\n"
      "  End Site\n  {\n   OFFSET 0 -1 0\n  }\n  End Site\n  {\n   OFFSET 0 -2 0\n  }\n }\n"
      " JOINT Leaf\n {\n  OFFSET 0 1 0\n  CHANNELS 1 Yrotation\n }\n}\n"
      "MOTION\nFrames: 1\nFrame Time: 0.01\n1 2 3 45\n";
  const ReadResult r = parse_bvh(text);
  REQUIRE_MESSAGE(r.ok(), r.error->message);
  REQUIRE(r.clip.joints.size() == 5);
  CHECK(r.clip.joints[1].name == "Bip01 L Thigh");
  CHECK(r.clip.joints[1].channels.empty());
  CHECK(r.clip.joints[2].name == "Bip01 L Thigh_End");
  CHECK(r.clip.joints[3].name == "Bip01 L Thigh_End2");
  CHECK(r.clip.joints[3].parent == 1);
  CHECK(r.clip.joints[4].name == "Leaf");
  CHECK(r.clip.joints[4].parent == 0);
  CHECK(r.clip.values == std::vector<double>{1, 2, 3, 45});
}

TEST_CASE("reader: numbers beyond a double's range") {
  const std::string lf = kSmallBvh;
  const ReadResult tiny = parse_bvh(replace_all(lf, "1e1", "-1e-400"));
  REQUIRE(tiny.ok());
  CHECK(tiny.clip.values[21] == 0.0);
  CHECK(std::signbit(tiny.clip.values[21]));
  const ReadResult tiny_fraction = parse_bvh(replace_all(lf, "1e1", "0." + std::string(400, '0') + "1"));
  REQUIRE(tiny_fraction.ok());
  CHECK(tiny_fraction.clip.values[21] == 0.0);
  const ReadResult subnormal = parse_bvh(replace_all(lf, "1e1", "4e-320"));
  REQUIRE(subnormal.ok());
  CHECK(subnormal.clip.values[21] > 0.0);
  CHECK_FALSE(parse_bvh(replace_all(lf, "1e1", "1e400")).ok());
  CHECK_FALSE(parse_bvh(replace_all(lf, "1e1", "1" + std::string(400, '0'))).ok());
  CHECK_FALSE(parse_bvh(replace_all(lf, "1e1", "0.001e999")).ok());
}

TEST_CASE("reader: frame times outside 1/240..1/24 s are read with a warning on their line") {
  const std::string lf = kSmallBvh;
  for (const char* usual : {"0.0083333", ".0083333", "0.0041667", "0.0416667", "0.04"}) {
    const ReadResult r = parse_bvh(replace_all(lf, "0.0333333", usual));
    REQUIRE(r.ok());
    CHECK_MESSAGE(r.warnings.empty(), usual);
  }
  for (const char* odd : {"1", "33.3", "0.001", "0.1"}) {
    const ReadResult r = parse_bvh(replace_all(lf, "0.0333333", odd));
    REQUIRE(r.ok());
    REQUIRE_MESSAGE(r.warnings.size() == 1, odd);
    CHECK(r.warnings[0].line == 18);
    CHECK(r.warnings[0].message.find("frame time") != std::string::npos);
  }
}

TEST_CASE("reader: a file read from disk is the same as its text") {
  const ReadResult r = read_bvh_file(tonus::test::shared_bvh("cmu_02_walk.bvh"));
  REQUIRE(r.ok());
  CHECK(r.clip.frame_count == 344);
}
