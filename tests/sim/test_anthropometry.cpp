// de Leva (1996) table and the HumanBodyBones tree shared by sim/ and host/.
#include <doctest/doctest.h>

#include <set>

#include "tonus/sim/anthropometry.hpp"
#include "tonus/sim/human_bones.hpp"

using namespace tonus::sim;

TEST_CASE("de Leva: segment masses add up to the whole body") {
  // Table 4 rounds every entry to 0.01 %, so the sum may miss 100 % by a few hundredths.
  CHECK(total_mass_fraction(Sex::male) == doctest::Approx(1.0).epsilon(2e-4));
  CHECK(total_mass_fraction(Sex::female) == doctest::Approx(1.0).epsilon(2e-4));
}

TEST_CASE("de Leva: the three trunk parts make up the paper's whole trunk") {
  // Whole trunk (Table 4): 43.46 % male, 42.57 % female.
  const auto trunk = [](Sex s) {
    return de_leva(Segment::upper_trunk, s).mass_fraction + de_leva(Segment::middle_trunk, s).mass_fraction +
           de_leva(Segment::lower_trunk, s).mass_fraction;
  };
  CHECK(trunk(Sex::male) == doctest::Approx(0.4346).epsilon(1e-9));
  CHECK(trunk(Sex::female) == doctest::Approx(0.4257).epsilon(1e-9));
}

TEST_CASE("de Leva: spot values of Table 4") {
  CHECK(de_leva(Segment::thigh, Sex::male).mass_fraction == 0.1416);
  CHECK(de_leva(Segment::thigh, Sex::female).com_fraction == 0.3612);
  CHECK(de_leva(Segment::hand, Sex::male).com_fraction == 0.7900);
  CHECK(de_leva(Segment::forearm, Sex::female).rg_longitudinal == 0.094);
  CHECK(de_leva(Segment::head, Sex::male).proximal == "VERT");
  CHECK(de_leva_subject(Sex::female).mass_kg == 61.9);
  for (const auto& table : {kDeLevaMale, kDeLevaFemale}) {
    for (const SegmentParams& p : table) {
      CAPTURE(p.name);
      CHECK(p.com_fraction > 0.0);
      CHECK(p.com_fraction < 1.0);
      CHECK(p.rg_longitudinal > 0.0);
      CHECK(p.length_m > 0.05);
    }
  }
}

TEST_CASE("HumanBodyBones tree: parents come first, names are unique and round-trip") {
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < kBoneCount; ++i) {
    const BoneInfo& b = kBones[i];
    CAPTURE(b.name);
    CHECK(index(b.bone) == i);
    CHECK(names.insert(b.name).second);
    CHECK(bone_from_name(b.name) == b.bone);
    if (i == 0) {
      CHECK_FALSE(b.parent.has_value());
    } else {
      REQUIRE(b.parent.has_value());
      CHECK(index(*b.parent) < i);
    }
    CHECK(mirror(mirror(b.bone)) == b.bone);
    CHECK(info(mirror(b.bone)).side == (b.side == Side::left    ? Side::right
                                        : b.side == Side::right ? Side::left
                                                                : Side::center));
  }
  CHECK(mirror(Bone::LeftToes) == Bone::RightToes);
  CHECK(mirror(Bone::RightShoulder) == Bone::LeftShoulder);
  CHECK_FALSE(bone_from_name("hips").has_value());
}
