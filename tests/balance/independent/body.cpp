#include "independent/body.hpp"

namespace tonus::indep {

namespace {

constexpr double kStature_mm = 1741.0;
constexpr double kLegToStature = (422.2 + 440.3) / kStature_mm;
constexpr double kFootToStature = 258.1 / kStature_mm;
constexpr double kHeadToStature = 242.9 / kStature_mm;
constexpr double kHandToForearm = 86.2 / 268.9;
constexpr double kSoleWidthToLength = 0.38;
constexpr double kHeelBehindAnkle = 0.20;  // of the foot length
constexpr double kTipBeyondToe = 0.25;

// Table 4's rows used here: head VERT-CERV, trunk CERV-MIDH, upper arm
// SJC-EJC, forearm EJC-WJC, hand WJC-MET3, thigh HJC-KJC, shank KJC-AJC,
// foot HEEL-TTIP (the head, trunk and shank from the table's alternative end
// points, which BVH joints stand for). The masses add up to 100 %.
constexpr std::array<SegmentParameters, kSegmentCount> kTable{{
    {"head", 0.0694, 0.5002},
    {"trunk", 0.4346, 0.5138},
    {"left upper arm", 0.0271, 0.5772},
    {"left forearm", 0.0162, 0.4574},
    {"left hand", 0.0061, 0.7900},
    {"left thigh", 0.1416, 0.4095},
    {"left shank", 0.0433, 0.4395},
    {"left foot", 0.0137, 0.4415},
    {"right upper arm", 0.0271, 0.5772},
    {"right forearm", 0.0162, 0.4574},
    {"right hand", 0.0061, 0.7900},
    {"right thigh", 0.1416, 0.4095},
    {"right shank", 0.0433, 0.4395},
    {"right foot", 0.0137, 0.4415},
}};

Vec3 along(const Vec3& from, const Vec3& to, double fraction) { return from + fraction * (to - from); }

}  // namespace

const std::array<SegmentParameters, kSegmentCount>& de_leva_male() { return kTable; }

Proportions proportions(const Sites& s) {
  double leg = 0.0;
  for (const std::size_t side : {std::size_t{0}, kRightOffset}) {
    leg += (s[left_knee + side] - s[left_hip + side]).norm() + (s[left_ankle + side] - s[left_knee + side]).norm();
  }
  Proportions p;
  p.stature_m = 0.5 * leg / kLegToStature;
  p.foot_length_m = kFootToStature * p.stature_m;
  p.sole_half_width_m = 0.5 * kSoleWidthToLength * p.foot_length_m;
  return p;
}

Foot place_foot(const Sites& s, std::size_t side, const Proportions& body, const Eigen::Vector2d& previous_axis) {
  const Vec3& ankle = s[left_ankle + side];
  const Vec3& toe = s[left_toe + side];
  Foot f;
  const Eigen::Vector2d ground = (toe - ankle).head<2>();
  f.axis = ground.norm() > 1e-6 ? Eigen::Vector2d(ground.normalized()) : previous_axis;
  const Vec3 u(f.axis.x(), f.axis.y(), 0.0);
  const double length = body.foot_length_m;
  f.heel = ankle - kHeelBehindAnkle * length * u;
  f.tip = toe + kTipBeyondToe * length * u;
  f.heel_point = f.heel + body.sole_half_width_m * u;
  f.toe_point = f.tip - body.sole_half_width_m * u;
  return f;
}

std::array<Vec3, kSegmentCount> segment_centres(const Sites& s, const Foot& left, const Foot& right,
                                                const Proportions& body) {
  std::array<Vec3, kSegmentCount> c;
  const Vec3 up = s[head] - s[neck];
  const Vec3 vertex = s[neck] + kHeadToStature * body.stature_m * (up.norm() > 1e-9 ? up.normalized() : Vec3::UnitZ());
  const Vec3 mid_hip = 0.5 * (s[left_hip] + s[right_hip]);
  c[0] = along(vertex, s[neck], kTable[0].com_fraction);
  c[1] = along(s[neck], mid_hip, kTable[1].com_fraction);
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t side = k * kRightOffset;
    const std::size_t i = 2 + 6 * k;
    const Vec3& wrist = s[left_wrist + side];
    const Vec3 metacarpal = wrist + kHandToForearm * (wrist - s[left_elbow + side]);
    const Foot& foot = k == 0 ? left : right;
    c[i] = along(s[left_shoulder + side], s[left_elbow + side], kTable[i].com_fraction);
    c[i + 1] = along(s[left_elbow + side], wrist, kTable[i + 1].com_fraction);
    c[i + 2] = along(wrist, metacarpal, kTable[i + 2].com_fraction);
    c[i + 3] = along(s[left_hip + side], s[left_knee + side], kTable[i + 3].com_fraction);
    c[i + 4] = along(s[left_knee + side], s[left_ankle + side], kTable[i + 4].com_fraction);
    c[i + 5] = along(foot.heel, foot.tip, kTable[i + 5].com_fraction);
  }
  return c;
}

}  // namespace tonus::indep
