// Body proportions from the legs, and de Leva's (1996) segments placed on
// the joint centres.
//
// de Leva P. (1996) Adjustments to Zatsiorsky-Seluyanov's segment inertia
// parameters. J. Biomech. 29(9), 1223-1230, table 4, males (stature
// 1741 mm): mass as a fraction of the body's, centre of mass as a fraction
// of the way from the segment's first end point to its second.
#pragma once

#include <array>
#include <string_view>

#include "independent/skeleton.hpp"

namespace tonus::indep {

struct Proportions {
  double stature_m = 0.0;
  double foot_length_m = 0.0;  // heel to toe tip
  double sole_half_width_m = 0.0;
};

// The stature from the mean hip-to-ankle length of both legs (de Leva's
// thigh 422.2 mm + shank to the ankle joint centre 440.3 mm = 0.4954 of the
// stature); the foot de Leva's 258.1 mm of 1741; the sole 38 % as broad as
// long (Winter 2009 gives a foot 0.152 of the stature long, 0.055 broad).
[[nodiscard]] Proportions proportions(const Sites& sites);

// A foot on the ground plane: its horizontal axis, heel and tip (the sole's
// ends), and the two contact points, heel and toe, each a sole's half width
// inside its end so that the points widened by that half width span the sole.
struct Foot {
  Eigen::Vector2d axis = Eigen::Vector2d::UnitX();
  Vec3 heel = Vec3::Zero(), tip = Vec3::Zero();
  Vec3 heel_point = Vec3::Zero(), toe_point = Vec3::Zero();
};

// The foot of one side (0 left, kRightOffset right). The axis is the
// ankle-to-toe direction on the ground (the previous one if the foot points
// straight down). The heel is a fifth of the foot's length behind the ankle
// (the ankle stands over the rear of the heel pad), the tip a quarter of it
// ahead of the toe joint (the ball of the foot is about three quarters of
// the way along); the heel at the ankle's height, the tip at the toe joint's.
[[nodiscard]] Foot place_foot(const Sites& sites, std::size_t side, const Proportions& body,
                              const Eigen::Vector2d& previous_axis);

// head, trunk, then per side (left first) upper arm, forearm, hand, thigh,
// shank, foot.
inline constexpr std::size_t kSegmentCount = 14;

struct SegmentParameters {
  std::string_view name;
  double mass_fraction;
  double com_fraction;  // from the first end point
};
[[nodiscard]] const std::array<SegmentParameters, kSegmentCount>& de_leva_male();

// Every segment's centre of mass. End points the skeletons lack are made
// from de Leva's lengths: the vertex (head top) up the neck-to-head line a
// head's length (242.9 mm of 1741) from the neck joint; the third
// metacarpal's head on the forearm's line beyond the wrist, 86.2/268.9 of
// the forearm's length (a straight wrist).
[[nodiscard]] std::array<Vec3, kSegmentCount> segment_centres(const Sites& sites, const Foot& left, const Foot& right,
                                                              const Proportions& body);

}  // namespace tonus::indep
