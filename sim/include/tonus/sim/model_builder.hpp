// Builds a Model and checks every field on the way: a bad model is refused
// with a message naming the body or geom and the field, never built.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "tonus/sim/model.hpp"

namespace tonus::sim {

struct BodySpec {
  std::string name;
  int parent = -1;  // index returned by add_body; -1 for the root
  JointType joint = JointType::fixed;
  Vec3 pos_in_parent = Vec3::Zero();
  Quat quat_in_parent = Quat::Identity();
  Vec3 hinge_axis = Vec3::UnitX();
  double mass_kg = 0.0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
  JointLimit limit;
  DriveDefaults drive;
  double armature = 0.0;  // kg*m^2 on each of the joint's dofs
};

struct GeomSpec {
  int body = 0;
  Shape shape;
  Pose local;
  Material material;
  bool collides_with_ground = true;
  bool collides_with_objects = true;
};

struct BuildResult {
  std::unique_ptr<Model> model;  // null when the build failed
  std::string error;             // why, naming the field
  explicit operator bool() const { return model != nullptr; }
};

class ModelBuilder {
 public:
  // Bodies must be added parent before child. Returns the body's index.
  int add_body(BodySpec spec);
  void add_geom(const GeomSpec& spec);

  ModelBuilder& timestep(double dt_s);
  ModelBuilder& integrator(Integrator i);
  ModelBuilder& gravity(const Vec3& g);
  ModelBuilder& ground(const Ground& g);
  ModelBuilder& features(const Features& f);
  ModelBuilder& solver(const SolverOptions& s);

  [[nodiscard]] BuildResult build() const;

 private:
  std::vector<BodySpec> bodies_;
  std::vector<GeomSpec> geoms_;
  double timestep_s_ = 1e-3;
  Integrator integrator_ = Integrator::euler;
  Vec3 gravity_ = Vec3(0.0, 0.0, -9.81);
  Ground ground_;
  Features features_;
  SolverOptions solver_;
};

// Inertia of uniform solids about their centre, in their own axes (capsule
// and cylinder along z), for builders and tests.
Mat3 box_inertia(double mass_kg, const Vec3& half_extents_m);
Mat3 sphere_inertia(double mass_kg, double radius_m);
Mat3 cylinder_inertia(double mass_kg, double radius_m, double half_length_m);

}  // namespace tonus::sim
