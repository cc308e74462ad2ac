// The analysis in its three parts, so the estimator family can place the
// segments once and differentiate once per cut-off for all its members.
#pragma once

#include <string>
#include <vector>

#include "tonus/host/balance/analysis.hpp"

namespace tonus::balance::detail {

// Segments of every frame, on the mass model of `opt`.
void place_all_segments(Analysis& a, const HumanMotion& motion, const AnalysisOptions& opt,
                        const ContactTrack* contacts);

// Each segment's acceleration and, with `angular`, the summed rate of the
// segments' own angular momentum per frame. False (and a.error) when the
// derivatives library refuses the series.
bool differentiate_segments(Analysis& a, const HumanMotion& motion, const derivatives::Params& params, bool angular,
                            std::vector<Vec3>& angular_rate);

// ZMP, support polygon and signed distance per frame, and the summary.
void evaluate_frames(Analysis& a, const HumanMotion& motion, const AnalysisOptions& opt,
                     const std::vector<Vec3>& angular_rate);

}  // namespace tonus::balance::detail
