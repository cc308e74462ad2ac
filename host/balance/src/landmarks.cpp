#include "tonus/host/balance/landmarks.hpp"

namespace tonus::balance {

std::string_view name(Landmark l) {
  const auto i = index(l);
  if (i < sim::kBoneCount) return sim::kBones[i].name;
  switch (l) {
    case Landmark::HeadTop: return "HeadTop";
    case Landmark::LeftHandTip: return "LeftHandTip";
    case Landmark::RightHandTip: return "RightHandTip";
    case Landmark::LeftToeTip: return "LeftToeTip";
    case Landmark::RightToeTip: return "RightToeTip";
    case Landmark::LeftHeel: return "LeftHeel";
    case Landmark::RightHeel: return "RightHeel";
    case Landmark::MidHip: return "MidHip";
    default: return "?";
  }
}

}  // namespace tonus::balance
