// Body segment inertia parameters of de Leva (1996), Table 4.
//
//   P. de Leva, "Adjustments to Zatsiorsky-Seluyanov's segment inertia
//   parameters", Journal of Biomechanics 29(9):1223-1230, 1996.
//
// One table, shared by the physics humanoid (sim/) and the ZMP analysis
// (host/): every fraction here is relative to body mass or to the segment's
// length between its two landmarks. Where the paper gives two definitions of
// a segment, the one whose landmarks are joint centres (or closest to them) is
// used, because tonus only knows joint positions from mocap skeletons:
//   head         VERT (vertex) -> CERV (C7), neck included  (Table 4, lower part)
//   upper trunk  CERV (C7) -> XYPH (xiphoid)                (lower part)
//   middle trunk XYPH -> OMPH (omphalion)
//   lower trunk  OMPH -> MIDH (mid hip joint centres)
//   upper arm    SJC -> EJC (shoulder -> elbow joint centre)
//   forearm      EJC -> WJC (wrist joint centre)
//   hand         WJC -> MET3 (third metacarpale)
//   thigh        HJC -> KJC (hip -> knee joint centre)
//   shank        KJC -> AJC (ankle joint centre)             (lower part)
//   foot         HEEL -> TTIP (tip of the longest toe)
// Radii of gyration are about the segment's centre of mass: `sagittal` about
// the antero-posterior axis, `transverse` about the medio-lateral axis,
// `longitudinal` about the axis through both landmarks. (The paper's column
// names leave room for the two transverse axes to be swapped; they differ by
// a few percent for every segment except the trunk parts.)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace tonus::sim {

enum class Sex : std::uint8_t { male, female };

enum class Segment : std::uint8_t {
  head,
  upper_trunk,
  middle_trunk,
  lower_trunk,
  upper_arm,
  forearm,
  hand,
  thigh,
  shank,
  foot,
};

inline constexpr std::size_t kSegmentCount = 10;

struct SegmentParams {
  std::string_view name;
  std::string_view proximal;  // landmark the length and the CM position are measured from
  std::string_view distal;
  double length_m;       // mean length in de Leva's sample
  double mass_fraction;  // of total body mass
  double com_fraction;   // CM distance from `proximal`, as a fraction of the length
  double rg_sagittal;    // radii of gyration, fractions of the length
  double rg_transverse;
  double rg_longitudinal;
};

// clang-format off
inline constexpr std::array<SegmentParams, kSegmentCount> kDeLevaMale{{
  {"head",         "VERT", "CERV", 0.2429, 0.0694, 0.5002, 0.303, 0.315, 0.261},
  {"upper_trunk",  "CERV", "XYPH", 0.2421, 0.1596, 0.5066, 0.505, 0.320, 0.465},
  {"middle_trunk", "XYPH", "OMPH", 0.2155, 0.1633, 0.4502, 0.482, 0.383, 0.468},
  {"lower_trunk",  "OMPH", "MIDH", 0.1457, 0.1117, 0.6115, 0.615, 0.551, 0.587},
  {"upper_arm",    "SJC",  "EJC",  0.2817, 0.0271, 0.5772, 0.285, 0.269, 0.158},
  {"forearm",      "EJC",  "WJC",  0.2689, 0.0162, 0.4574, 0.276, 0.265, 0.121},
  {"hand",         "WJC",  "MET3", 0.0862, 0.0061, 0.7900, 0.628, 0.513, 0.401},
  {"thigh",        "HJC",  "KJC",  0.4222, 0.1416, 0.4095, 0.329, 0.329, 0.149},
  {"shank",        "KJC",  "AJC",  0.4403, 0.0433, 0.4395, 0.251, 0.246, 0.102},
  {"foot",         "HEEL", "TTIP", 0.2581, 0.0137, 0.4415, 0.257, 0.245, 0.124},
}};

inline constexpr std::array<SegmentParams, kSegmentCount> kDeLevaFemale{{
  {"head",         "VERT", "CERV", 0.2437, 0.0668, 0.4841, 0.271, 0.295, 0.261},
  {"upper_trunk",  "CERV", "XYPH", 0.2280, 0.1545, 0.5050, 0.466, 0.314, 0.449},
  {"middle_trunk", "XYPH", "OMPH", 0.2053, 0.1465, 0.4512, 0.433, 0.354, 0.415},
  {"lower_trunk",  "OMPH", "MIDH", 0.1815, 0.1247, 0.4920, 0.433, 0.402, 0.444},
  {"upper_arm",    "SJC",  "EJC",  0.2751, 0.0255, 0.5754, 0.278, 0.260, 0.148},
  {"forearm",      "EJC",  "WJC",  0.2643, 0.0138, 0.4559, 0.261, 0.257, 0.094},
  {"hand",         "WJC",  "MET3", 0.0780, 0.0056, 0.7474, 0.531, 0.454, 0.335},
  {"thigh",        "HJC",  "KJC",  0.3685, 0.1478, 0.3612, 0.369, 0.364, 0.162},
  {"shank",        "KJC",  "AJC",  0.4386, 0.0481, 0.4352, 0.267, 0.263, 0.092},
  {"foot",         "HEEL", "TTIP", 0.2283, 0.0129, 0.4014, 0.299, 0.279, 0.139},
}};
// clang-format on

// The subjects the table was measured on (de Leva 1996, Table 4 header).
struct ReferenceSubject {
  double stature_m;
  double mass_kg;
};
inline constexpr ReferenceSubject kDeLevaMaleSubject{1.741, 73.0};
inline constexpr ReferenceSubject kDeLevaFemaleSubject{1.735, 61.9};

constexpr std::size_t index(Segment s) { return static_cast<std::size_t>(s); }

constexpr const SegmentParams& de_leva(Segment s, Sex sex) {
  return sex == Sex::male ? kDeLevaMale[index(s)] : kDeLevaFemale[index(s)];
}

constexpr ReferenceSubject de_leva_subject(Sex sex) {
  return sex == Sex::male ? kDeLevaMaleSubject : kDeLevaFemaleSubject;
}

// Mass fraction of the whole body: the bilateral segments (arms, legs) count twice.
constexpr bool is_bilateral(Segment s) { return index(s) >= index(Segment::upper_arm); }

constexpr double total_mass_fraction(Sex sex) {
  double sum = 0.0;
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto s = static_cast<Segment>(i);
    sum += de_leva(s, sex).mass_fraction * (is_bilateral(s) ? 2.0 : 1.0);
  }
  return sum;
}

}  // namespace tonus::sim
