// The ZMP against closed forms: a static pose puts it under the centre of
// mass, a cart-table (linear inverted pendulum) trajectory gives
// p = x - (z_c / g) xdd, and the support polygon queries are exact.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "tonus/host/balance/mass_model.hpp"
#include "tonus/host/balance/polygon.hpp"
#include "tonus/host/balance/zmp.hpp"

using namespace tonus::balance;

namespace {

// A plausible standing skeleton (Z up, facing +x), metres.
LandmarkFrame standing() {
  using tonus::sim::Bone;
  LandmarkFrame f{};
  const auto set = [&](Landmark l, double x, double y, double z) { f[index(l)] = Vec3(x, y, z); };
  const auto bone = [&](Bone b, double x, double y, double z) { set(joint_of(b), x, y, z); };
  bone(Bone::Hips, 0, 0, 0.95);
  bone(Bone::Spine, 0, 0, 1.05);
  bone(Bone::Chest, 0, 0, 1.25);
  bone(Bone::Neck, 0, 0, 1.45);
  bone(Bone::Head, 0, 0, 1.55);
  set(Landmark::HeadTop, 0, 0, 1.72);
  for (const double s : {1.0, -1.0}) {
    const bool left = s > 0;
    bone(left ? Bone::LeftShoulder : Bone::RightShoulder, 0, 0.03 * s, 1.42);
    bone(left ? Bone::LeftUpperArm : Bone::RightUpperArm, 0, 0.18 * s, 1.42);
    bone(left ? Bone::LeftLowerArm : Bone::RightLowerArm, 0, 0.20 * s, 1.12);
    bone(left ? Bone::LeftHand : Bone::RightHand, 0.02, 0.20 * s, 0.86);
    set(left ? Landmark::LeftHandTip : Landmark::RightHandTip, 0.02, 0.20 * s, 0.78);
    bone(left ? Bone::LeftUpperLeg : Bone::RightUpperLeg, 0, 0.09 * s, 0.92);
    bone(left ? Bone::LeftLowerLeg : Bone::RightLowerLeg, 0.01, 0.09 * s, 0.50);
    bone(left ? Bone::LeftFoot : Bone::RightFoot, 0, 0.09 * s, 0.08);
    bone(left ? Bone::LeftToes : Bone::RightToes, 0.14, 0.09 * s, 0.02);
    set(left ? Landmark::LeftToeTip : Landmark::RightToeTip, 0.19, 0.09 * s, 0.01);
    set(left ? Landmark::LeftHeel : Landmark::RightHeel, -0.06, 0.09 * s, 0.0);
  }
  set(Landmark::MidHip, 0, 0, 0.92);
  return f;
}

}  // namespace

TEST_CASE("mass model: de Leva's parts add up to the body mass, and place a plausible centre of mass") {
  const MassModel m = make_mass_model(80.0, tonus::sim::Sex::male);
  double total = 0.0;
  for (const SegmentPart& p : m.parts) total += p.mass_kg;
  CHECK(total == doctest::Approx(80.0).epsilon(1e-12));
  const SegmentFrame s = place_segments(m, standing());
  const Vec3 com = centre_of_mass(m, s);
  // An adult's centre of mass stands at about 55-57 % of the stature (1.72 m here).
  CHECK(com.z() / 1.72 == doctest::Approx(0.56).epsilon(0.04));
  CHECK(std::abs(com.y()) < 1e-12);  // symmetric
  // The thigh's centre of mass at de Leva's 40.95 % from the hip.
  const SegmentState& thigh = s[10];
  const Vec3 hip(0, 0.09, 0.92), knee(0.01, 0.09, 0.50);
  CHECK((thigh.com - (hip + 0.4095 * (knee - hip))).norm() < 1e-12);
}

TEST_CASE("mass model: the trunk along the spine joints, or straight from the hips to the neck") {
  const MassModel spine = make_mass_model(70.0, tonus::sim::Sex::male);
  const MassModel straight = make_mass_model(70.0, tonus::sim::Sex::male, TrunkModel::straight);
  CHECK(spine.trunk == TrunkModel::spine);
  // Spine joints on the hips-neck line: the same placement either way.
  const LandmarkFrame upright = standing();
  const SegmentFrame a = place_segments(spine, upright), b = place_segments(straight, upright);
  for (std::size_t i = 0; i < kSegmentParts; ++i) CHECK((a[i].com - b[i].com).norm() < 1e-12);
  // A chest 6 cm forward of the line: the spine model's trunk follows it, the
  // straight one keeps its parts on the line from the mid-hip point to the neck.
  LandmarkFrame bent = upright;
  bent[index(joint_of(tonus::sim::Bone::Chest))].x() += 0.06;
  const SegmentFrame sb = place_segments(spine, bent), tb = place_segments(straight, bent);
  for (std::size_t i = 1; i <= 3; ++i) {
    CHECK(std::abs(tb[i].com.x()) < 1e-12);
    CHECK(tb[i].com.z() == doctest::Approx(a[i].com.z()).epsilon(1e-9));
  }
  CHECK(sb[2].com.x() > 0.02);  // the middle trunk, around the chest joint
  // Everything but the trunk is placed the same.
  for (const std::size_t i : {std::size_t{0}, std::size_t{4}, std::size_t{10}, std::size_t{15}})
    CHECK((sb[i].com - tb[i].com).norm() < 1e-12);
}

TEST_CASE("ZMP of a static pose is the ground projection of the centre of mass") {
  const MassModel m = make_mass_model(70.0, tonus::sim::Sex::female);
  const SegmentFrame s = place_segments(m, standing());
  std::array<Vec3, kSegmentParts> still;  // (Eigen vectors are not zeroed by {})
  still.fill(Vec3::Zero());
  for (const double ground : {0.0, 0.05, -0.3}) {
    const ZmpResult z = zero_moment_point(m, {&s, &still, Vec3::Zero()}, ground);
    REQUIRE(z.defined);
    const Vec3 com = centre_of_mass(m, s);
    CHECK(z.zmp.x() == doctest::Approx(com.x()).epsilon(1e-12).scale(1.0));
    CHECK(z.zmp.y() == doctest::Approx(com.y()).epsilon(1e-12).scale(1.0));
    CHECK(z.support_ratio == doctest::Approx(1.0));
  }
}

TEST_CASE("ZMP of a cart-table (linear inverted pendulum) motion matches p = x - z_c xdd / g") {
  // Every segment moves with the same horizontal sinusoid at constant height:
  // the body is one point mass at the centre of mass (x(t) = x0 + A sin(w t)).
  const MassModel m = make_mass_model(60.0, tonus::sim::Sex::male);
  const LandmarkFrame base = standing();
  const double a = 0.05, w = 2.0 * M_PI * 0.8, g = 9.81;
  for (const double t : {0.0, 0.1, 0.37, 0.9}) {
    LandmarkFrame f = base;
    const double dx = a * std::sin(w * t), xdd = -a * w * w * std::sin(w * t);
    for (Vec3& p : f) p.x() += dx;
    const SegmentFrame s = place_segments(m, f);
    std::array<Vec3, kSegmentParts> acc;
    acc.fill(Vec3(xdd, 0.0, 0.0));
    const ZmpResult z = zero_moment_point(m, {&s, &acc, Vec3::Zero()}, 0.0, g);
    const Vec3 com = centre_of_mass(m, s);
    CHECK(z.zmp.x() == doctest::Approx(com.x() - com.z() * xdd / g).epsilon(1e-12).scale(1.0));
  }
}

TEST_CASE("ZMP: free fall has none, the angular momentum rate shifts it by dL/(m g)") {
  const MassModel m = make_mass_model(70.0, tonus::sim::Sex::male);
  const SegmentFrame s = place_segments(m, standing());
  std::array<Vec3, kSegmentParts> fall;
  fall.fill(Vec3(0, 0, -9.81));
  CHECK_FALSE(zero_moment_point(m, {&s, &fall, Vec3::Zero()}, 0.0).defined);
  std::array<Vec3, kSegmentParts> still;
  still.fill(Vec3::Zero());
  const ZmpResult plain = zero_moment_point(m, {&s, &still, Vec3::Zero()}, 0.0);
  const ZmpResult spun = zero_moment_point(m, {&s, &still, Vec3(2.0, 3.0, 0.0)}, 0.0);
  CHECK(spun.zmp.x() - plain.zmp.x() == doctest::Approx(-3.0 / (70.0 * 9.81)));
  CHECK(spun.zmp.y() - plain.zmp.y() == doctest::Approx(2.0 / (70.0 * 9.81)));
}

TEST_CASE("support polygon queries: hull, signed distance, nearest point, inset") {
  const std::vector<Vec2> pts{{0, 0}, {0.3, 0}, {0.3, 0.1}, {0, 0.1}, {0.1, 0.05}, {0.3, 0.05}};
  const ConvexPolygon sq = convex_hull(pts);
  CHECK(sq.vertices.size() == 4);
  CHECK(signed_distance(sq, Vec2(0.15, 0.05)) == doctest::Approx(-0.05));
  CHECK(signed_distance(sq, Vec2(0.4, 0.05)) == doctest::Approx(0.1));
  CHECK(signed_distance(sq, Vec2(0.4, 0.2)) == doctest::Approx(std::hypot(0.1, 0.1)));
  CHECK((nearest_point(sq, Vec2(0.4, 0.2)) - Vec2(0.3, 0.1)).norm() < 1e-12);
  CHECK((nearest_point(sq, Vec2(0.2, 0.05)) - Vec2(0.2, 0.05)).norm() == 0.0);
  const Vec2 in = nearest_point_inset(sq, Vec2(0.15, -0.2), 0.01);
  CHECK(signed_distance(sq, in) == doctest::Approx(-0.01));
  // Degenerate polygons: a point and a segment have no inside.
  const ConvexPolygon seg = convex_hull(std::vector<Vec2>{{0, 0}, {1, 0}});
  CHECK(signed_distance(seg, Vec2(0.5, 0.0)) == doctest::Approx(0.0));
  CHECK(signed_distance(seg, Vec2(0.5, 0.2)) == doctest::Approx(0.2));
  CHECK(std::isinf(signed_distance(ConvexPolygon{}, Vec2(0, 0))));
  // Random points: the hull contains every point, and is convex.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec2> cloud(200);
  for (Vec2& p : cloud) p = Vec2(u(rng), 0.3 * u(rng));
  const ConvexPolygon hull = convex_hull(cloud);
  for (const Vec2& p : cloud) CHECK(signed_distance(hull, p) <= 1e-12);
}
