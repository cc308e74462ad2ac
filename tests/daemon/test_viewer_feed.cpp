// What the viewer is sent, checked against physics rather than against the
// feed's own arithmetic: standing still, the ZMP lies under the centre of
// mass, inside the soles' support polygon; swaying, it swings by the
// cart-table model's closed form; every bone is posed where the simulation
// has it; a cube on the hand shows as an object whose contacts carry its weight.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "daemon_fixtures.hpp"
#include "tonus/host/balance/polygon.hpp"
#include "tonus/host/daemon/viewer_feed.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;
using namespace tonus::daemon;

namespace {

sim::Vec3 centre_of_mass(const sim::Model& model, const sim::Data& d) {
  sim::Vec3 com = sim::Vec3::Zero();
  double mass = 0.0;
  for (int i = 0; i < model.nbody; ++i) {
    const double m = model.bodies[static_cast<std::size_t>(i)].mass_kg;
    com += m * d.xcom[static_cast<std::size_t>(i)];
    mass += m;
  }
  return com / mass;
}

}  // namespace

TEST_CASE("viewer feed: standing still, the ZMP is under the centre of mass, inside the soles' support polygon") {
  const sim::Model& model = test::daemon_humanoid();
  std::string error;
  PhysicsCoreConfig cfg;  // tonusd's: the hips carried (kinematic root), the body off the ground
  cfg.viewer_every_ticks = 10;
  auto core = PhysicsCore::create(model, cfg, error);
  REQUIRE(core);
  const std::int64_t t0 = 1'000'000;
  int k = 0;
  ViewerFrameBuilder builder(model);
  viewer::Frame f;
  for (; k < 1500; ++k) {
    core->tick(t0 + std::int64_t{1000} * k);
    if (core->viewer_snapshots().update()) builder.build(core->viewer_snapshots().read_slot(), f);
  }
  const sim::Vec3 com = centre_of_mass(model, core->controller().sim_b());
  REQUIRE(f.zmp.has_value());
  MESSAGE("ZMP " << (*f.zmp)[0] << ", " << (*f.zmp)[1] << "; COM " << com.x() << ", " << com.y() << "; "
                 << f.support.size() << " support vertices");
  CHECK(std::hypot((*f.zmp)[0] - com.x(), (*f.zmp)[1] - com.y()) < 0.005);  // static: under the centre of mass
  balance::ConvexPolygon poly;
  for (const viewer::Vec2& p : f.support) poly.vertices.emplace_back(p[0], p[1]);
  REQUIRE(f.support.size() >= 3);
  CHECK(balance::signed_distance(poly, balance::Vec2((*f.zmp)[0], (*f.zmp)[1])) < -0.02);  // well inside
  // The support spans both feet: wider than a hip's width, longer than a foot's half.
  double min_y = 1e9, max_y = -1e9, min_x = 1e9, max_x = -1e9;
  for (const viewer::Vec2& p : f.support) {
    min_x = std::min(min_x, p[0]);
    max_x = std::max(max_x, p[0]);
    min_y = std::min(min_y, p[1]);
    max_y = std::max(max_y, p[1]);
  }
  CHECK(max_y - min_y > 0.15);
  CHECK(max_x - min_x > 0.12);

  // Every bone where the simulation has it.
  const sim::Data& b = core->controller().sim_b();
  REQUIRE(f.avatar.size() == static_cast<std::size_t>(model.nbody));
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Vec3& p = b.xbody[static_cast<std::size_t>(i)].pos;
    const viewer::Vec3& q = f.avatar[static_cast<std::size_t>(i)].pos;
    CHECK(std::abs(q[0] - p.x()) + std::abs(q[1] - p.y()) + std::abs(q[2] - p.z()) < 1e-3);  // a few ticks apart
  }
  CHECK(f.reference.size() == f.avatar.size());
  CHECK(f.stiffness.size() == 4);
  CHECK(f.objects.empty());

  // A cube dropped at the right hand (by the side, it falls past it): an object in the frames, and once
  // it rests on the ground, contacts that carry its weight.
  Command c;
  c.kind = Command::Kind::gift;
  c.id = 7;
  c.gift = GiftKind::cube;
  REQUIRE(core->push_command(c));
  for (int n = 0; n < 1500; ++n, ++k) {
    core->tick(t0 + std::int64_t{1000} * k);
    if (core->viewer_snapshots().update()) builder.build(core->viewer_snapshots().read_slot(), f);
  }
  REQUIRE(f.objects.size() == 1);
  CHECK(f.objects[0].id == 7);
  CHECK(f.objects[0].kind == "cube");
  double up_n = 0.0;
  for (const viewer::ContactFrame& cf : f.contacts) up_n += cf.force_n[2];
  MESSAGE("the cube's contacts carry " << up_n << " N up (" << f.contacts.size() << " contacts; cube at "
                                       << f.objects[0].pos[2] << " m)");
  CHECK(f.objects[0].pos[2] < 0.06);                   // on the ground (an 8 cm cube)
  CHECK(up_n == doctest::Approx(9.81).epsilon(0.05));  // the 1 kg cube's weight
}

TEST_CASE("viewer feed: a body swaying sideways has its ZMP where the cart-table model puts it") {
  // The hips carried along y = A sin(w t): the whole body's centre of mass
  // accelerates by -A w^2 sin(w t), so the ZMP swings A w^2 c_z / g further
  // than the centre of mass, in phase with it (closed form, not the feed's code).
  const sim::Model& model = test::daemon_humanoid();
  std::string error;
  PhysicsCoreConfig cfg;
  cfg.viewer_every_ticks = 10;
  auto core = PhysicsCore::create(model, cfg, error);
  REQUIRE(core);
  ViewerFrameBuilder builder(model);
  viewer::Frame f;
  const double amplitude_m = 0.04, w = 2.0 * 3.14159265358979 * 0.8;
  PoseSample pose;
  pose.qpos = model.qpos0;
  const double stand_z = pose.qpos[2];
  double peak_offset = 0.0, peak_predicted = 0.0;
  for (int k = 0; k < 5000; ++k) {
    const std::int64_t now = 1'000'000 + std::int64_t{1000} * k;
    if (k % 8 == 0) {
      pose.t_us = now;
      pose.qpos[1] = amplitude_m * std::sin(w * k * 1e-3);
      pose.qpos[2] = stand_z;
      core->push_pose(pose);
    }
    core->tick(now);
    if (!core->viewer_snapshots().update()) continue;
    builder.build(core->viewer_snapshots().read_slot(), f);
    if (k < 2500 || !f.zmp) continue;  // settled into the sway
    const sim::Vec3 com = centre_of_mass(model, core->controller().sim_b());
    peak_offset = std::max(peak_offset, std::abs((*f.zmp)[1] - com.y()));
    peak_predicted = std::max(peak_predicted, amplitude_m * w * w * com.z() / 9.81);
  }
  MESSAGE("ZMP beyond the centre of mass: peak " << peak_offset << " m; cart-table: " << peak_predicted << " m");
  CHECK(peak_offset == doctest::Approx(peak_predicted).epsilon(0.2));
}

TEST_CASE("viewer feed: the scene names every bone and gives the shapes the page draws") {
  const sim::Model& model = test::daemon_humanoid();
  const viewer::Scene scene = make_viewer_scene(model, "live");
  REQUIRE(scene.bones.size() == static_cast<std::size_t>(model.nbody));
  CHECK(scene.bones[0].parent == -1);
  CHECK(scene.groups == std::vector<std::string>{"right_arm", "left_arm", "trunk", "legs"});
  bool hand_in_right_arm = false;
  for (const viewer::BoneInfo& b : scene.bones) {
    if (b.name == "RightHand") hand_in_right_arm = b.group == 0;
  }
  CHECK(hand_in_right_arm);
  CHECK(scene.geoms.size() >= scene.bones.size() - 2);  // nearly every bone has a shape
  for (const viewer::GeomInfo& g : scene.geoms) {
    CHECK((g.shape == "capsule" || g.shape == "sphere" || g.shape == "box"));
    CHECK(g.bone >= 0);
    CHECK(g.bone < model.nbody);
  }
  CHECK(std::find(scene.gift_bones.begin(), scene.gift_bones.end(), "Chest") != scene.gift_bones.end());
  CHECK(scene.rate_hz == doctest::Approx(1.0 / model.timestep_s));
}
