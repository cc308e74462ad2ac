// Robustness: every truncation, every one-byte corruption, deletion and
// duplication of a small file gives an error or a valid clip, never a crash
// (the asan preset runs this under ASan and UBSan).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>

#include "bvh_samples.hpp"
#include "support/mutate.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/motion/kinematics.hpp"

using namespace tonus::motion;

namespace {

struct Tally {
  std::size_t accepted = 0;
  std::size_t refused = 0;
};

// An error names a line of the text; an accepted clip is well-formed, poses
// every frame, and writes and reads back.
void check_outcome(std::string_view text, Tally& tally) {
  const ReadResult r = parse_bvh(text);
  if (!r.ok()) {
    ++tally.refused;
    const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n') +
                                                std::count(text.begin(), text.end(), '\r'));
    CHECK(r.error->line >= 1);
    CHECK(r.error->line <= lines + 1);
    CHECK_FALSE(r.error->message.empty());
    return;
  }
  ++tally.accepted;
  REQUIRE_FALSE(check_clip(r.clip).has_value());
  for (std::size_t f = 0; f < r.clip.frame_count; ++f)
    CHECK(forward_kinematics(r.clip, f).size() == r.clip.joints.size());
  const std::string written = write_bvh(r.clip);
  const ReadResult back = parse_bvh(written);
  REQUIRE(back.ok());
  CHECK(write_bvh(back.clip) == written);
}

}  // namespace

TEST_CASE("corruption: every truncation of the small file, LF and CRLF") {
  for (const bool crlf : {false, true}) {
    std::string text;
    for (const char c : std::string_view(tonus::test::kSmallBvh)) {
      if (c == '\n' && crlf) text += '\r';
      text += c;
    }
    // Only cuts that keep all 27 values can give a clip ("...0 0 9" reads 9
    // for the last value: a cut inside a number cannot be told apart).
    const std::size_t last_value = text.rfind("90");
    Tally tally;
    for (std::size_t cut = 0; cut < text.size(); ++cut) {
      CAPTURE(cut);
      check_outcome(std::string_view(text).substr(0, cut), tally);
      if (cut <= last_value) CHECK_FALSE(parse_bvh(std::string_view(text).substr(0, cut)).ok());
    }
    CHECK(tally.refused == last_value + 1);
  }
}

TEST_CASE("corruption: every value of every byte of the small file") {
  const std::string text = tonus::test::kSmallBvh;
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  Tally tally;
  tonus::test::for_each_byte_corruption(bytes, [&tally](std::span<const std::uint8_t> corrupted) {
    check_outcome(std::string_view(reinterpret_cast<const char*>(corrupted.data()), corrupted.size()), tally);
  });
  MESSAGE("one-byte corruptions: ", tally.accepted, " accepted, ", tally.refused, " refused");
  CHECK(tally.refused > tally.accepted);
  CHECK(tally.accepted > 0);  // e.g. a digit changed into another digit
}

TEST_CASE("corruption: deleting any byte, duplicating any line") {
  const std::string text = tonus::test::kSmallBvh;
  Tally tally;
  for (std::size_t i = 0; i < text.size(); ++i) check_outcome(text.substr(0, i) + text.substr(i + 1), tally);
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = text.find('\n', start) + 1;
    check_outcome(text.substr(0, end) + text.substr(start), tally);
    start = end;
  }
  CHECK(tally.refused > 0);
}
