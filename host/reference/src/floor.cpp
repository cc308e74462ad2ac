#include "floor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tonus/sim/data.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::reference::detail {
namespace {

using sim::Bone;

// The lowest world z of a posed shape.
double lowest_z(const sim::Shape& s, const sim::Pose& x) {
  switch (s.type) {
    case sim::ShapeType::sphere: return x.pos.z() - s.radius_m;
    case sim::ShapeType::capsule: return x.pos.z() - s.half_length_m * std::abs(x.rot(2, 2)) - s.radius_m;
    case sim::ShapeType::box: return x.pos.z() - x.rot.row(2).cwiseAbs().dot(s.half_extents_m);
    case sim::ShapeType::plane: break;
  }
  return std::numeric_limits<double>::infinity();
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

FloorFit fit_floor(const sim::Model& model, const std::vector<std::array<double, sim::kMaxQpos>>& qpos,
                   const balance::ContactTrack& contacts) {
  FloorFit fit;
  if (qpos.empty()) return fit;
  const auto data = sim::make_data(model);
  const std::array<std::array<Bone, 2>, 2> feet{{{Bone::LeftFoot, Bone::LeftToes}, {Bone::RightFoot, Bone::RightToes}}};
  std::vector<double> in_contact, lowest;
  for (std::size_t f = 0; f < qpos.size(); ++f) {
    data->qpos = qpos[f];
    sim::forward_kinematics(model, *data);
    double frame_low = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < 2; ++k) {
      double low = std::numeric_limits<double>::infinity();
      for (std::size_t g = 0; g < static_cast<std::size_t>(model.ngeom); ++g) {
        const auto body = static_cast<std::size_t>(model.geoms[g].body);
        if (body == sim::index(feet[k][0]) || body == sim::index(feet[k][1])) {
          low = std::min(low, lowest_z(model.geoms[g].shape, data->xgeom[g]));
        }
      }
      if (!std::isfinite(low)) continue;
      frame_low = std::min(frame_low, low);
      if (f < contacts.frames.size() && contacts.frames[f][k].any()) in_contact.push_back(low);
    }
    if (std::isfinite(frame_low)) lowest.push_back(frame_low);
  }
  if (!in_contact.empty()) {
    fit.offset_m = -median(in_contact);
    fit.samples = in_contact.size();
  } else if (!lowest.empty()) {
    const auto p5 = lowest.begin() + static_cast<std::ptrdiff_t>(lowest.size() / 20);
    std::nth_element(lowest.begin(), p5, lowest.end());
    fit.offset_m = -*p5;
  }
  return fit;
}

}  // namespace tonus::reference::detail
