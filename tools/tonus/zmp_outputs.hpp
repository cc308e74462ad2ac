// The balance report's files: CSV per frame, a JSON report, an SVG plot.
#pragma once

#include <string>
#include <vector>

#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/family.hpp"
#include "tonus/host/balance/filter.hpp"

namespace tonus::tools {

struct ZmpReport {
  std::string input;
  std::string convention;
  std::string unit;
  bool unit_guessed = false;
  bool tpose_excluded = false;
  double frame_time_s = 0.0;
  std::size_t frames_total = 0;
  const balance::FilterResult* filter = nullptr;
  const balance::AppliedCorrection* applied = nullptr;  // the written clip, measured against the original
  // The original and the written clip under every estimator of the family.
  const balance::FamilyVerdict* family_before = nullptr;
  const balance::FamilyVerdict* family_after = nullptr;
  double max_correction_rad = 0.0;
  std::size_t lookahead_frames = 0;
  bool online = false;          // the streaming filter made the correction
  double online_mean_us = 0.0;  // its cost per frame
  double online_max_us = 0.0;
  double online_window_cutoff_hz = 0.0;            // its smoothing's cut-off
  balance::Vec2 forward = balance::Vec2::UnitX();  // the plots' forward axis in the ground plane
};

// The direction the motion travels (or, in place, the way the body faces at the start).
balance::Vec2 travel_direction(const balance::HumanMotion& motion, const balance::Analysis& analysis);

bool write_zmp_csv(const std::string& path, const ZmpReport& r, std::string& error);
bool write_zmp_json(const std::string& path, const ZmpReport& r, std::string& error);
bool write_zmp_svg(const std::string& path, const ZmpReport& r, std::string& error);

}  // namespace tonus::tools
