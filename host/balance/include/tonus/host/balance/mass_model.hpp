// Where the body's mass is, frame by frame: de Leva's (1996) 16 segments
// (the table in sim/include/tonus/sim/anthropometry.hpp, shared with the
// physics humanoid) placed on a motion's landmarks and scaled to a body mass.
//
// The trunk is split along the polyline from the mid-hip point up the spine
// joints the skeleton has (Spine, Chest, ...) to the neck base, at de Leva's
// length proportions of the lower, middle and upper trunk, so any number of
// spine joints works.
#pragma once

#include <array>
#include <cstddef>

#include "tonus/host/balance/landmarks.hpp"
#include "tonus/sim/anthropometry.hpp"

namespace tonus::balance {

inline constexpr std::size_t kSegmentParts = 16;

struct SegmentPart {
  sim::Segment segment;
  double mass_kg;
};

// Where the trunk's three parts lie. `spine`: along the polyline from the
// mid-hip point up the spine joints to the neck base, so a bending spine
// carries them. `straight`: on the straight line from the mid-hip point to the
// neck base, where a model with one rigid trunk (de Leva's CERV-MIDH segment:
// the independent estimator of the tests, the audit of issue 14) has them.
// The two differ by centimetres of ZMP on lively clips (docs/balance.md).
enum class TrunkModel { spine, straight };

struct MassModel {
  std::array<SegmentPart, kSegmentParts> parts{};
  double total_mass_kg = 0.0;
  sim::Sex sex = sim::Sex::male;
  TrunkModel trunk = TrunkModel::spine;
};

MassModel make_mass_model(double body_mass_kg, sim::Sex sex, TrunkModel trunk = TrunkModel::spine);

// Per frame: each part's centre of mass, and its longitudinal axis (unit,
// proximal to distal) and length, for the angular-momentum term.
struct SegmentState {
  Vec3 com = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double length_m = 0.0;
};
using SegmentFrame = std::array<SegmentState, kSegmentParts>;

SegmentFrame place_segments(const MassModel& model, const LandmarkFrame& frame);

// Whole-body centre of mass of a placed frame.
Vec3 centre_of_mass(const MassModel& model, const SegmentFrame& segments);

}  // namespace tonus::balance
