// ZMP analysis of a whole motion: the mass model on the landmarks, segment
// accelerations by the derivatives library (Kalman RTS smoothing, then spline
// differentiation), the ZMP per frame, foot contacts and the support polygon,
// and how far outside the polygon the ZMP goes.
#pragma once

#include <optional>
#include <vector>

#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/balance/landmarks.hpp"
#include "tonus/host/balance/mass_model.hpp"
#include "tonus/host/balance/polygon.hpp"
#include "tonus/host/derivatives/params.hpp"

namespace tonus::balance {

struct AnalysisOptions {
  double body_mass_kg = 70.0;  // scales forces, not the ZMP (which depends on mass ratios only)
  sim::Sex sex = sim::Sex::male;
  TrunkModel trunk = TrunkModel::spine;  // where the trunk's mass lies (mass_model.hpp)
  bool angular_momentum = false;         // the full form: add the segments' angular momentum rate
  derivatives::Params derivatives;
  ContactOptions contacts;
  double gravity = 9.81;
  double tolerance_m = 0.001;  // a ZMP outside the polygon by more than this counts as outside
};

struct FrameAnalysis {
  bool analysed = false;     // false for excluded frames (a leading T-pose)
  bool airborne = false;     // no foot in contact: no support polygon
  bool zmp_defined = false;  // false in free fall (vertical force under 10 % of the weight)
  Vec2 zmp = Vec2::Zero();
  Vec3 com = Vec3::Zero();
  double outside_m = 0.0;  // signed distance to the support polygon: > 0 outside, < 0 inside
  ConvexPolygon support;
};

struct AnalysisSummary {
  std::size_t frames = 0;            // analysed frames
  std::size_t frames_outside = 0;    // supported frames with the ZMP outside by more than the tolerance
  std::size_t frames_airborne = 0;   // no foot down: neither inside nor outside
  std::size_t frames_undefined = 0;  // a foot down but the ZMP undefined (near free fall)
  double max_outside_m = 0.0;
  double rms_outside_m = 0.0;  // over the frames outside
};

struct Analysis {
  MassModel mass;
  ContactTrack contacts;
  std::vector<FrameAnalysis> frames;
  std::vector<SegmentFrame> segments;                          // per frame
  std::vector<std::array<Vec3, kSegmentParts>> accelerations;  // per frame
  std::vector<Vec3> angular_momentum_rate;                     // per frame (zero in the particle form)
  AnalysisSummary summary;
  std::string error;  // non-empty: the differentiation refused the series (too short, ...)
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// `contacts`, when given, is used instead of detecting them again (the filter
// keeps the feet, so it keeps their contacts).
Analysis analyse(const HumanMotion& motion, const AnalysisOptions& options, const ContactTrack* contacts = nullptr);

}  // namespace tonus::balance
