#include "reference_checks.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::reference::test {
namespace {

using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr double kDeg = 180.0 / M_PI;

double angle_deg(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * kDeg; }

// Every corner of a box, the ends of a capsule, a sphere's bottom: the lowest z.
double lowest_z(const sim::Shape& s, const sim::Pose& x) {
  double low = std::numeric_limits<double>::infinity();
  if (s.type == sim::ShapeType::box) {
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner((c & 1) != 0 ? 1.0 : -1.0, (c & 2) != 0 ? 1.0 : -1.0, (c & 4) != 0 ? 1.0 : -1.0);
      low = std::min(low, x.apply(corner.cwiseProduct(s.half_extents_m)).z());
    }
  } else if (s.type == sim::ShapeType::capsule) {
    for (const double end : {-1.0, 1.0}) low = std::min(low, x.apply(Vec3(0, 0, end * s.half_length_m)).z());
    low -= s.radius_m;
  } else if (s.type == sim::ShapeType::sphere) {
    low = x.pos.z() - s.radius_m;
  }
  return low;
}

struct Segment {
  Bone from, to;
  std::size_t kind;
};
constexpr Segment kSegments[] = {
    {Bone::LeftUpperArm, Bone::LeftLowerArm, 0},
    {Bone::RightUpperArm, Bone::RightLowerArm, 0},
    {Bone::LeftLowerArm, Bone::LeftHand, 1},
    {Bone::RightLowerArm, Bone::RightHand, 1},
    {Bone::LeftUpperLeg, Bone::LeftLowerLeg, 2},
    {Bone::RightUpperLeg, Bone::RightLowerLeg, 2},
    {Bone::LeftLowerLeg, Bone::LeftFoot, 3},
    {Bone::RightLowerLeg, Bone::RightFoot, 3},
    {Bone::Spine, Bone::Chest, 4},
    {Bone::Neck, Bone::Head, 5},
};

}  // namespace

const sim::Model& humanoid() {
  static const std::unique_ptr<sim::Model> model = [] {
    sim::BuildResult r = sim::build_humanoid(sim::HumanoidSpec{});
    REQUIRE_MESSAGE(r, r.error);
    return std::move(r.model);
  }();
  return *model;
}

balance::Conversion load(const std::string& path) {
  motion::ReadResult r = motion::read_bvh_file(path);
  REQUIRE_MESSAGE(r.ok(), path << ": " << (r.error ? r.error->message : std::string()));
  const balance::MapResult mapping = balance::map_skeleton(r.clip);
  REQUIRE_MESSAGE(mapping.ok(), mapping.error);
  balance::Conversion c = balance::convert_motion(r.clip, mapping, balance::ConvertOptions{});
  REQUIRE_MESSAGE(c.ok(), c.error);
  return c;
}

Spread spread(std::vector<double> v) {
  Spread s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]; };
  s.median = at(0.5);
  s.p95 = at(0.95);
  s.max = v.back();
  return s;
}

SwingTwist swing_twist(const Quat& q_in, const Vec3& t_in) {
  const Quat q = q_in.normalized();
  const Vec3 t = t_in.normalized();
  const Vec3 u = q * t;
  SwingTwist st;
  st.swing = std::acos(std::clamp(t.dot(u), -1.0, 1.0));
  // What is left after undoing the swing turns about t only.
  const Quat twist = sim::quat_from_two_vectors(t, u).conjugate() * q;
  const Vec3 n = t.unitOrthogonal();
  st.twist = std::atan2(t.dot(n.cross(twist * n)), n.dot(twist * n));
  return st;
}

Figures evaluate(const sim::Model& m, const balance::HumanMotion& motion, const ClipReference& ref) {
  Figures fig;
  REQUIRE(ref.qpos.size() == motion.size());
  const auto data = sim::make_data(m);
  const balance::ContactTrack contacts = balance::detect_contacts(motion, balance::ContactOptions{});
  std::array<std::vector<double>, kSegmentKinds> angles;
  std::vector<double> all, feet;
  const Vec3 mid = 0.5 * (m.bodies[sim::index(Bone::LeftUpperLeg)].pos_in_parent +
                          m.bodies[sim::index(Bone::RightUpperLeg)].pos_in_parent);
  for (std::size_t f = motion.first_frame; f < motion.size(); ++f) {
    const balance::MotionFrame& clip = motion.frames[f];
    data->qpos = ref.qpos[f];
    sim::forward_kinematics(m, *data);
    for (const Segment& s : kSegments) {
      const Vec3 ours = data->xbody[sim::index(s.to)].pos - data->xbody[sim::index(s.from)].pos;
      const Vec3 theirs = clip.p[sim::index(s.to)] - clip.p[sim::index(s.from)];
      if (theirs.norm() < 0.01) continue;  // the clip has no such segment
      const double a = angle_deg(ours, theirs);
      angles[s.kind].push_back(a);
      all.push_back(a);
    }
    for (std::size_t k = 0; k < 2; ++k) {
      if (f >= contacts.frames.size() || !contacts.frames[f][k].any()) continue;
      const Bone foot = k == 0 ? Bone::LeftFoot : Bone::RightFoot, toes = k == 0 ? Bone::LeftToes : Bone::RightToes;
      double low = std::numeric_limits<double>::infinity();
      for (std::size_t g = 0; g < static_cast<std::size_t>(m.ngeom); ++g) {
        const auto b = static_cast<std::size_t>(m.geoms[g].body);
        if (b == sim::index(foot) || b == sim::index(toes))
          low = std::min(low, lowest_z(m.geoms[g].shape, data->xgeom[g]));
      }
      feet.push_back(std::abs(low));
    }
    const Vec3 hip = data->xbody[0].apply(mid);
    const Vec3 want = ref.scale * clip.p[balance::index(balance::Landmark::MidHip)];
    fig.root_path_error_m = std::max(fig.root_path_error_m, (hip - want).head<2>().norm());

    for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
      const sim::Body& b = m.bodies[i];
      const auto a = static_cast<std::size_t>(b.qpos_adr);
      const auto& q = ref.qpos[f];
      if (b.joint == sim::JointType::hinge) {
        if (q[a] < b.limit.lower_rad - 1e-9 || q[a] > b.limit.upper_rad + 1e-9) {
          ++fig.limit_violations;
          fig.worst_violation = std::string(b.name_view()) + " frame " + std::to_string(f);
        }
        continue;
      }
      const std::size_t qa = a + (b.joint == sim::JointType::free ? 3 : 0);
      const Quat now(q[qa], q[qa + 1], q[qa + 2], q[qa + 3]);
      fig.max_quat_norm_error = std::max(fig.max_quat_norm_error, std::abs(now.norm() - 1.0));
      if (f > motion.first_frame) {
        const auto& p = ref.qpos[f - 1];
        const Quat before(p[qa], p[qa + 1], p[qa + 2], p[qa + 3]);
        if (now.coeffs().dot(before.coeffs()) < 0.0) ++fig.sign_flips;
        if (b.joint == sim::JointType::ball) {
          fig.max_step_deg = std::max(fig.max_step_deg, now.angularDistance(before) * kDeg);
        }
      }
      if (b.joint == sim::JointType::ball) {
        const SwingTwist st = swing_twist(now, b.limit.twist_axis);
        if (st.swing > b.limit.swing_max_rad + 1e-9 || st.twist < b.limit.lower_rad - 1e-9 ||
            st.twist > b.limit.upper_rad + 1e-9) {
          ++fig.limit_violations;
          fig.worst_violation = std::string(b.name_view()) + " frame " + std::to_string(f) + " swing " +
                                std::to_string(st.swing) + " twist " + std::to_string(st.twist);
        }
      }
    }
  }
  for (std::size_t k = 0; k < kSegmentKinds; ++k) fig.segment_deg[k] = spread(angles[k]);
  fig.all_deg = spread(all);
  fig.contact_foot_z_m = spread(feet);
  return fig;
}

}  // namespace tonus::reference::test
