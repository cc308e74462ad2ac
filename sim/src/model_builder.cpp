// ModelBuilder: validation and the derived index tables (dof addresses, the
// dof tree the sparse factorisation walks).
#include "tonus/sim/model_builder.hpp"

#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>

namespace tonus::sim {
namespace {

bool finite(double x) { return std::isfinite(x); }
bool finite(const Vec3& v) { return all_finite(v); }
bool finite(const Quat& q) { return finite(q.w()) && finite(q.vec()); }
bool finite(const Mat3& m) { return m.allFinite(); }

class Checker {
 public:
  explicit Checker(std::string& error) : error_(error) {}
  // Records the first failure only: the message names the first bad field.
  bool fail(const std::string& where, const std::string& what) {
    if (error_.empty()) error_ = where + ": " + what;
    return false;
  }

 private:
  std::string& error_;
};

std::string body_where(std::size_t i, const BodySpec& b) {
  std::ostringstream s;
  s << "body " << i << " '" << b.name << "'";
  return s.str();
}

bool check_unit_quat(Checker& c, const std::string& where, const std::string& field, const Quat& q) {
  if (!finite(q)) return c.fail(where, field + " is not finite");
  if (std::abs(q.norm() - 1.0) > 1e-6)
    return c.fail(where, field + " is not a unit quaternion (norm " + std::to_string(q.norm()) + ")");
  return true;
}

bool check_inertia(Checker& c, const std::string& where, const Mat3& inertia) {
  if (!finite(inertia)) return c.fail(where, "inertia is not finite");
  if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + inertia.cwiseAbs().maxCoeff())) {
    return c.fail(where, "inertia is not symmetric");
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
  const Vec3& ev = eig.eigenvalues();  // ascending
  if (!(ev(0) > 0.0)) return c.fail(where, "inertia is not positive definite");
  // A real mass distribution obeys the triangle inequality of principal moments.
  if (ev(0) + ev(1) < ev(2) * (1.0 - 1e-9)) return c.fail(where, "inertia violates the triangle inequality");
  return true;
}

bool check_material(Checker& c, const std::string& where, const Material& m) {
  if (!finite(m.friction) || m.friction < 0.0) return c.fail(where, "friction must be finite and >= 0");
  if (!finite(m.restitution) || m.restitution < 0.0 || m.restitution > 1.0) {
    return c.fail(where, "restitution must be in [0, 1]");
  }
  return true;
}

bool check_body(Checker& c, std::size_t i, const BodySpec& b) {
  const std::string where = body_where(i, b);
  if (b.name.empty()) return c.fail(where, "name is empty");
  if (b.name.size() >= kNameLength) return c.fail(where, "name is longer than " + std::to_string(kNameLength - 1));
  if (i == 0 && b.parent != -1) return c.fail(where, "the root's parent must be -1 (the world)");
  if (i > 0 && (b.parent < 0 || static_cast<std::size_t>(b.parent) >= i)) {
    return c.fail(where, "parent must be an earlier body (parents before children)");
  }
  if (b.joint == JointType::free && i != 0) return c.fail(where, "only the root may have a free joint");
  if (!finite(b.pos_in_parent)) return c.fail(where, "pos_in_parent is not finite");
  if (!check_unit_quat(c, where, "quat_in_parent", b.quat_in_parent)) return false;
  if (b.joint == JointType::hinge && (!finite(b.hinge_axis) || b.hinge_axis.norm() < 1e-9)) {
    return c.fail(where, "hinge_axis must be a finite non-zero vector");
  }
  if (!finite(b.mass_kg) || b.mass_kg <= 0.0) return c.fail(where, "mass_kg must be finite and > 0");
  if (!finite(b.com)) return c.fail(where, "com is not finite");
  if (!check_inertia(c, where, b.inertia)) return false;
  const JointLimit& l = b.limit;
  if (l.enabled) {
    if (b.joint == JointType::hinge || b.joint == JointType::ball) {
      if (!finite(l.lower_rad) || !finite(l.upper_rad) || l.lower_rad > l.upper_rad) {
        return c.fail(where, "limit: lower_rad must be <= upper_rad, both finite");
      }
    }
    if (b.joint == JointType::ball) {
      if (!finite(l.swing_max_rad) || l.swing_max_rad <= 0.0 || l.swing_max_rad > M_PI) {
        return c.fail(where, "limit: swing_max_rad must be in (0, pi]");
      }
      if (!finite(l.twist_axis) || l.twist_axis.norm() < 1e-9)
        return c.fail(where, "limit: twist_axis must be non-zero");
      if (l.lower_rad < -M_PI || l.upper_rad > M_PI) return c.fail(where, "limit: twist range must lie in [-pi, pi]");
    }
  }
  if (!finite(b.armature) || b.armature < 0.0) return c.fail(where, "armature must be finite and >= 0");
  const DriveDefaults& d = b.drive;
  if (!finite(d.kp) || d.kp < 0.0) return c.fail(where, "drive.kp must be finite and >= 0");
  if (!finite(d.kd) || d.kd < 0.0) return c.fail(where, "drive.kd must be finite and >= 0");
  if (!finite(d.torque_limit_nm) || d.torque_limit_nm < 0.0) {
    return c.fail(where, "drive.torque_limit_nm must be finite and >= 0 (0 = unlimited)");
  }
  return true;
}

bool check_geom(Checker& c, std::size_t i, const GeomSpec& g, std::size_t nbody) {
  const std::string where = "geom " + std::to_string(i);
  if (g.body < 0 || static_cast<std::size_t>(g.body) >= nbody) return c.fail(where, "body index out of range");
  if (g.shape.type == ShapeType::plane) return c.fail(where, "planes belong to the ground, not to bodies");
  if (!shape_is_valid(g.shape)) return c.fail(where, "shape sizes must be finite and > 0");
  if (!finite(g.local.pos) || !finite(g.local.rot)) return c.fail(where, "local pose is not finite");
  if ((g.local.rot * g.local.rot.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      g.local.rot.determinant() < 0.0) {
    return c.fail(where, "local.rot is not a rotation");
  }
  return check_material(c, where, g.material);
}

bool check_options(Checker& c, double dt, const Vec3& g, const Ground& ground, const SolverOptions& s) {
  if (!finite(dt) || dt <= 0.0 || dt > 0.05) return c.fail("model", "timestep_s must be in (0, 0.05]");
  if (!finite(g)) return c.fail("model", "gravity is not finite");
  if (!finite(ground.normal) || ground.normal.norm() < 1e-9) return c.fail("ground", "normal must be non-zero");
  if (!finite(ground.offset_m)) return c.fail("ground", "offset_m is not finite");
  if (!check_material(c, "ground", ground.material)) return false;
  if (s.iterations < 1 || s.iterations > 10000) return c.fail("solver", "iterations must be in [1, 10000]");
  if (!finite(s.tolerance) || s.tolerance < 0.0) return c.fail("solver", "tolerance must be >= 0");
  if (!finite(s.baumgarte) || s.baumgarte < 0.0 || s.baumgarte > 1.0)
    return c.fail("solver", "baumgarte must be in [0, 1]");
  if (!finite(s.penetration_slop_m) || s.penetration_slop_m < 0.0)
    return c.fail("solver", "penetration_slop_m must be >= 0");
  if (!finite(s.contact_margin_m) || s.contact_margin_m < 0.0) return c.fail("solver", "contact_margin_m must be >= 0");
  if (!finite(s.restitution_threshold_mps) || s.restitution_threshold_mps < 0.0) {
    return c.fail("solver", "restitution_threshold_mps must be >= 0");
  }
  if (!finite(s.limit_margin_rad) || s.limit_margin_rad < 0.0) return c.fail("solver", "limit_margin_rad must be >= 0");
  if (s.torque_limit_passes < 0 || s.torque_limit_passes > 16)
    return c.fail("solver", "torque_limit_passes must be in [0, 16]");
  if (!finite(s.max_speed) || s.max_speed <= 0.0) return c.fail("solver", "max_speed must be > 0");
  if (s.max_contacts < 1 || s.max_contacts > static_cast<int>(kMaxContacts))
    return c.fail("solver", "max_contacts must be in [1, kMaxContacts]");
  return true;
}

}  // namespace

int ModelBuilder::add_body(BodySpec spec) {
  bodies_.push_back(std::move(spec));
  return static_cast<int>(bodies_.size()) - 1;
}

void ModelBuilder::add_geom(const GeomSpec& spec) { geoms_.push_back(spec); }

ModelBuilder& ModelBuilder::timestep(double dt_s) {
  timestep_s_ = dt_s;
  return *this;
}
ModelBuilder& ModelBuilder::integrator(Integrator i) {
  integrator_ = i;
  return *this;
}
ModelBuilder& ModelBuilder::gravity(const Vec3& g) {
  gravity_ = g;
  return *this;
}
ModelBuilder& ModelBuilder::ground(const Ground& g) {
  ground_ = g;
  return *this;
}
ModelBuilder& ModelBuilder::features(const Features& f) {
  features_ = f;
  return *this;
}
ModelBuilder& ModelBuilder::solver(const SolverOptions& s) {
  solver_ = s;
  return *this;
}

BuildResult ModelBuilder::build() const {
  BuildResult result;
  Checker c(result.error);
  if (bodies_.empty()) {
    c.fail("model", "no bodies");
    return result;
  }
  if (bodies_.size() > kMaxBodies) {
    c.fail("model",
           std::to_string(bodies_.size()) + " bodies exceed the capacity kMaxBodies = " + std::to_string(kMaxBodies));
    return result;
  }
  if (geoms_.size() > kMaxGeoms) {
    c.fail("model",
           std::to_string(geoms_.size()) + " geoms exceed the capacity kMaxGeoms = " + std::to_string(kMaxGeoms));
    return result;
  }
  std::set<std::string> names;
  std::size_t nv = 0, nq = 0;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!check_body(c, i, bodies_[i])) return result;
    if (!names.insert(bodies_[i].name).second) {
      c.fail(body_where(i, bodies_[i]), "name is used twice");
      return result;
    }
    nv += static_cast<std::size_t>(joint_dofs(bodies_[i].joint));
    nq += static_cast<std::size_t>(joint_qpos(bodies_[i].joint));
  }
  if (nv > kMaxDofs) {
    c.fail("model", std::to_string(nv) + " degrees of freedom exceed kMaxDofs = " + std::to_string(kMaxDofs));
    return result;
  }
  if (nq > kMaxQpos) {
    c.fail("model", std::to_string(nq) + " position coordinates exceed kMaxQpos = " + std::to_string(kMaxQpos));
    return result;
  }
  for (std::size_t i = 0; i < geoms_.size(); ++i) {
    if (!check_geom(c, i, geoms_[i], bodies_.size())) return result;
  }
  if (!check_options(c, timestep_s_, gravity_, ground_, solver_)) return result;
  if (integrator_ == Integrator::rk4 && (features_.contacts || features_.limits)) {
    c.fail(
        "model",
        "the rk4 integrator takes contact- and limit-free models only (disable features.contacts and features.limits)");
    return result;
  }

  auto m = std::make_unique<Model>();
  m->nbody = static_cast<int>(bodies_.size());
  m->ngeom = static_cast<int>(geoms_.size());
  m->timestep_s = timestep_s_;
  m->integrator = integrator_;
  m->gravity = gravity_;
  m->ground = ground_;
  m->ground.normal.normalize();
  m->features = features_;
  m->solver = solver_;
  int dof = 0, qadr = 0;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const BodySpec& s = bodies_[i];
    Body& b = m->bodies[i];
    std::memcpy(b.name.data(), s.name.data(), s.name.size());
    b.parent = s.parent;
    b.joint = s.joint;
    b.pos_in_parent = s.pos_in_parent;
    b.quat_in_parent = s.quat_in_parent.normalized();
    b.hinge_axis = s.hinge_axis.normalized();
    b.mass_kg = s.mass_kg;
    b.com = s.com;
    b.inertia = 0.5 * (s.inertia + s.inertia.transpose());
    b.limit = s.limit;
    b.limit.twist_axis = s.limit.twist_axis.normalized();
    b.drive = s.drive;
    b.armature = s.armature;
    b.dof_adr = dof;
    b.dof_num = joint_dofs(s.joint);
    b.qpos_adr = qadr;
    b.qpos_num = joint_qpos(s.joint);
    const int parent_last = s.parent >= 0 ? m->bodies[static_cast<std::size_t>(s.parent)].last_path_dof : -1;
    for (int k = 0; k < b.dof_num; ++k) {
      const auto d = static_cast<std::size_t>(dof) + static_cast<std::size_t>(k);
      m->dof_body[d] = static_cast<int>(i);
      m->dof_parent[d] = k == 0 ? parent_last : dof + k - 1;
      m->dof_kp[d] = s.drive.kp;
      m->dof_kd[d] = s.drive.kd;
    }
    b.last_path_dof = b.dof_num > 0 ? dof + b.dof_num - 1 : parent_last;
    const auto parent_u = static_cast<std::size_t>(s.parent);
    m->body_path_dofs[i] = s.parent >= 0 ? m->body_path_dofs[parent_u] : 0;
    for (int k = 0; k < b.dof_num; ++k) m->body_path_dofs[i] |= std::uint64_t{1} << static_cast<unsigned>(dof + k);
    m->body_ancestors[i] = (s.parent >= 0 ? m->body_ancestors[parent_u] : 0U) | (1U << static_cast<unsigned>(i));
    // Rest configuration: a free root starts at its given pose, joints at identity / zero.
    auto q = m->qpos0.begin() + qadr;
    switch (s.joint) {
      case JointType::free:
        q[0] = s.pos_in_parent.x();
        q[1] = s.pos_in_parent.y();
        q[2] = s.pos_in_parent.z();
        q[3] = b.quat_in_parent.w();
        q[4] = b.quat_in_parent.x();
        q[5] = b.quat_in_parent.y();
        q[6] = b.quat_in_parent.z();
        break;
      case JointType::ball: q[0] = 1.0; break;
      case JointType::hinge:
      case JointType::fixed: break;
    }
    dof += b.dof_num;
    qadr += b.qpos_num;
  }
  m->nv = dof;
  m->nq = qadr;
  for (std::size_t i = 0; i < geoms_.size(); ++i) {
    const GeomSpec& s = geoms_[i];
    Geom& g = m->geoms[i];
    g.body = s.body;
    g.shape = s.shape;
    g.local = s.local;
    g.material = s.material;
    g.collides_with_ground = s.collides_with_ground;
    g.collides_with_objects = s.collides_with_objects;
  }
  result.model = std::move(m);
  return result;
}

Mat3 box_inertia(double mass_kg, const Vec3& h) {
  const Vec3 s = (2.0 * h).cwiseAbs2();
  return (mass_kg / 12.0 * Vec3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y())).asDiagonal();
}

Mat3 sphere_inertia(double mass_kg, double r) { return (0.4 * mass_kg * r * r) * Mat3::Identity(); }

Mat3 cylinder_inertia(double mass_kg, double r, double half_length_m) {
  const double len = 2.0 * half_length_m;
  const double transverse = mass_kg * (3.0 * r * r + len * len) / 12.0;
  return Vec3(transverse, transverse, 0.5 * mass_kg * r * r).asDiagonal();
}

}  // namespace tonus::sim
