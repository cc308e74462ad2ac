// MJCF export: the body tree nested as MuJoCo wants it, with every number
// written at full precision (the validation compares to 1e-9).
#include "tonus/sim/mjcf.hpp"

#include <cmath>
#include <cstddef>
#include <iomanip>
#include <sstream>

namespace tonus::sim {
namespace {

using std::size_t;

std::string num(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}
std::string vec(const Vec3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }
std::string quat(const Quat& q) { return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z()); }

// Collision filtering as our step does it: bodies meet the ground and the
// objects, not each other (unless self-collision is on); objects meet all.
constexpr int kBodyType = 1, kGroundType = 2, kObjectType = 2;
constexpr int kGroundAffinity = 1, kObjectAffinity = 3;

std::string friction(const Material& m) { return num(m.friction) + " 0.005 0.0001"; }

std::string shape_attrs(const Shape& s) {
  switch (s.type) {
    case ShapeType::sphere: return "type=\"sphere\" size=\"" + num(s.radius_m) + "\"";
    case ShapeType::capsule: return "type=\"capsule\" size=\"" + num(s.radius_m) + " " + num(s.half_length_m) + "\"";
    case ShapeType::box: return "type=\"box\" size=\"" + vec(s.half_extents_m) + "\"";
    case ShapeType::plane: return "type=\"plane\" size=\"0 0 1\"";
  }
  return {};
}

class Writer {
 public:
  Writer(const Model& m, const MjcfOptions& o) : m_(m), o_(o) {}

  std::string run() {
    const Features& f = m_.features;
    out_ << "<mujoco model=\"" << o_.model_name << "\">\n";
    out_ << "  <compiler angle=\"radian\" inertiafromgeom=\"false\" autolimits=\"true\"/>\n";
    out_ << "  <option timestep=\"" << num(m_.timestep_s) << "\" gravity=\"" << vec(m_.gravity) << "\" integrator=\""
         << (o_.integrator_euler ? "Euler" : "RK4") << "\">\n";
    out_ << "    <flag contact=\"" << (f.contacts ? "enable" : "disable") << "\" limit=\""
         << (f.limits ? "enable" : "disable") << "\" gravity=\"" << (f.gravity ? "enable" : "disable") << "\"/>\n";
    out_ << "  </option>\n";
    out_ << "  <size njmax=\"2000\" nconmax=\"500\"/>\n";
    out_ << "  <worldbody>\n";
    if (m_.ground.enabled) {
      const Ground& g = m_.ground;
      out_ << "    <geom name=\"ground\" type=\"plane\" size=\"0 0 1\" pos=\"" << vec(g.normal * g.offset_m)
           << "\" zaxis=\"" << vec(g.normal) << "\" friction=\"" << friction(g.material) << "\" contype=\""
           << kGroundType << "\" conaffinity=\"" << kGroundAffinity << "\"/>\n";
    }
    if (m_.nbody > 0) body(0, 2);
    if (o_.objects_from != nullptr) objects(*o_.objects_from);
    out_ << "  </worldbody>\n";
    out_ << "</mujoco>\n";
    return out_.str();
  }

 private:
  void body(size_t i, int depth) {
    const Body& b = m_.bodies[i];
    const std::string pad(static_cast<size_t>(depth) * 2, ' ');
    out_ << pad << "<body name=\"" << b.name_view() << "\" pos=\"" << vec(b.pos_in_parent) << "\" quat=\""
         << quat(b.quat_in_parent) << "\">\n";
    joint(b, pad + "  ");
    out_ << pad << "  <inertial pos=\"" << vec(b.com) << "\" mass=\"" << num(b.mass_kg) << "\" fullinertia=\""
         << num(b.inertia(0, 0)) << " " << num(b.inertia(1, 1)) << " " << num(b.inertia(2, 2)) << " "
         << num(b.inertia(0, 1)) << " " << num(b.inertia(0, 2)) << " " << num(b.inertia(1, 2)) << "\"/>\n";
    const int affinity = m_.features.self_collision ? kBodyType : 0;
    for (size_t g = 0; g < static_cast<size_t>(m_.ngeom); ++g) {
      const Geom& geom = m_.geoms[g];
      if (static_cast<size_t>(geom.body) != i) continue;
      const Quat q(geom.local.rot);
      out_ << pad << "  <geom " << shape_attrs(geom.shape) << " pos=\"" << vec(geom.local.pos) << "\" quat=\""
           << quat(q) << "\" friction=\"" << friction(geom.material) << "\" contype=\""
           << (geom.collides_with_ground || geom.collides_with_objects ? kBodyType : 0) << "\" conaffinity=\""
           << affinity << "\"/>\n";
    }
    for (size_t c = i + 1; c < static_cast<size_t>(m_.nbody); ++c) {
      if (m_.bodies[c].parent == static_cast<int>(i)) body(c, depth + 1);
    }
    out_ << pad << "</body>\n";
  }

  void joint(const Body& b, const std::string& pad) {
    const std::string name = std::string(b.name_view());
    std::string spring;
    if (b.armature > 0.0) spring += " armature=\"" + num(b.armature) + "\"";
    if (o_.drives_as_springs && (b.joint == JointType::ball || b.joint == JointType::hinge)) {
      spring += " stiffness=\"" + num(b.drive.kp) + "\" damping=\"" + num(b.drive.kd) + "\"";
    }
    switch (b.joint) {
      case JointType::free: out_ << pad << "<joint name=\"" << name << "\" type=\"free\"" << spring << "/>\n"; break;
      case JointType::ball:
        out_ << pad << "<joint name=\"" << name << "\" type=\"ball\"" << spring;
        if (b.limit.enabled) out_ << " range=\"0 " << num(b.limit.swing_max_rad) << "\"";
        out_ << "/>\n";
        break;
      case JointType::hinge:
        out_ << pad << "<joint name=\"" << name << "\" type=\"hinge\" axis=\"" << vec(b.hinge_axis) << "\"" << spring;
        if (b.limit.enabled) out_ << " range=\"" << num(b.limit.lower_rad) << " " << num(b.limit.upper_rad) << "\"";
        out_ << "/>\n";
        break;
      case JointType::fixed: break;
    }
  }

  void objects(const Data& d) {
    for (size_t i = 0; i < kMaxObjects; ++i) {
      const Object& o = d.objects[i];
      if (!o.active) continue;
      out_ << "    <body name=\"object" << i << "\" pos=\"" << vec(o.pos) << "\" quat=\"" << quat(o.quat) << "\">\n";
      out_ << "      <freejoint name=\"object" << i << "\"/>\n";
      out_ << "      <inertial pos=\"0 0 0\" mass=\"" << num(o.mass_kg) << "\" diaginertia=\"" << vec(o.inertia_diag)
           << "\"/>\n";
      out_ << "      <geom " << shape_attrs(o.shape) << " friction=\"" << friction(o.material) << "\" contype=\""
           << kObjectType << "\" conaffinity=\"" << kObjectAffinity << "\"/>\n";
      out_ << "    </body>\n";
    }
  }

  const Model& m_;
  const MjcfOptions& o_;
  std::ostringstream out_;
};

}  // namespace

std::string to_mjcf(const Model& model, const MjcfOptions& options) { return Writer(model, options).run(); }

}  // namespace tonus::sim
