// The estimator family. ZMP estimators differ by centimetres on real capture
// (the smoothing cut-off decides how much of the capture's jitter reaches the
// accelerations; the full form adds the segments' own angular momentum), so a
// motion is called balanced only when it is so under every member, never
// under the one estimator a filter optimised. The members are the analysis at
// cut-offs of 4, 6, 8 and 12 Hz, each in the particle and the full form, on
// one set of contacts.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "tonus/host/balance/analysis.hpp"

namespace tonus::balance {

inline constexpr std::array<double, 4> kFamilyCutoffsHz = {4.0, 6.0, 8.0, 12.0};
inline constexpr std::size_t kFamilySize = 2 * kFamilyCutoffsHz.size();

// A frame outside by more than this under a member counts against the motion
// (the goal: at most kFamilyAllowedShare of the supported frames).
inline constexpr double kFamilyThreshold_m = 0.01;
inline constexpr double kFamilyAllowedShare = 0.02;

// `base` with each cut-off, particle then full form (everything else as given).
std::vector<AnalysisOptions> estimator_family(const AnalysisOptions& base);
// With both_trunks, followed by the same with the other trunk model
// (mass_model.hpp): the estimators' spread in where the trunk's mass lies,
// beside their smoothing's.
std::vector<AnalysisOptions> estimator_family(const AnalysisOptions& base, bool both_trunks);

// Every member's analysis on the same contacts. The segments are placed once
// per trunk model and differentiated once per cut-off and trunk: the cost is
// about those, not the members'. An error in any member is every member's error.
std::vector<Analysis> analyse_family(const HumanMotion& motion, const std::vector<AnalysisOptions>& members,
                                     const ContactTrack& contacts);

struct MemberVerdict {
  double cutoff_hz = 0.0;
  bool full = false;
  TrunkModel trunk = TrunkModel::spine;
  std::size_t supported = 0;  // analysed frames with a foot down and the ZMP defined
  std::size_t outside = 0;    // of those, outside by more than the threshold
  double max_outside_m = 0.0;
  [[nodiscard]] double share() const {
    return supported == 0 ? 0.0 : static_cast<double>(outside) / static_cast<double>(supported);
  }
};

struct FamilyVerdict {
  std::vector<MemberVerdict> members;
  std::size_t worst = 0;  // the member with the most frames outside
  double threshold_m = kFamilyThreshold_m;
  [[nodiscard]] bool balanced(double allowed_share = kFamilyAllowedShare) const {
    return members.empty() || members[worst].share() <= allowed_share;
  }
};

FamilyVerdict family_verdict(const std::vector<Analysis>& analyses, const std::vector<AnalysisOptions>& members,
                             double threshold_m = kFamilyThreshold_m);

}  // namespace tonus::balance
