// Shapes against a plane (z = 0 of its frame, +z out, infinite: a half-space).
#include <array>
#include <utility>

#include "narrow.hpp"

namespace tonus::sim::narrow {
namespace {

// Contact of a core point at signed height h over the plane, inflated by r.
void add_over_plane(const Vec3& core, double h, double r, const Vec3& n, Candidates& out) {
  out.add_from_b(core - h * n, n, h - r);
}

}  // namespace

void sphere_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out) {
  const Vec3 n = pb.rot.col(2);
  add_over_plane(pa.pos, n.dot(pa.pos - pb.pos), a.radius_m, n, out);
}

void capsule_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out) {
  // The gap is linear along the core, so its ends bound it: the deepest end
  // always, both when the capsule lies (nearly) flat within the margin.
  const Vec3 n = pb.rot.col(2);
  for (const double side : {-1.0, 1.0}) {
    const Vec3 end = capsule_end(a, pa, side);
    add_over_plane(end, n.dot(end - pb.pos), a.radius_m, n, out);
  }
}

void box_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out) {
  // The four lowest corners within the margin: a box lying flat gives its
  // bottom face, a tilted one its lowest edge or corner.
  const Vec3 n = pb.rot.col(2);
  const Vec3& h = a.half_extents_m;
  struct Corner {
    Vec3 p;
    double height;
  };
  std::array<Corner, 8> corners{};
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec3 local((i & 1U) != 0 ? h.x() : -h.x(), (i & 2U) != 0 ? h.y() : -h.y(), (i & 4U) != 0 ? h.z() : -h.z());
    const Vec3 p = pa.apply(local);
    corners[i] = {p, n.dot(p - pb.pos)};
  }
  // Insertion sort (std::stable_sort may allocate); stable, so equal heights
  // keep corner order and the result is deterministic.
  for (std::size_t i = 1; i < corners.size(); ++i) {
    for (std::size_t j = i; j > 0 && corners[j].height < corners[j - 1].height; --j)
      std::swap(corners[j], corners[j - 1]);
  }
  for (std::size_t i = 0; i < kMaxPointsPerPair; ++i) add_over_plane(corners[i].p, corners[i].height, 0.0, n, out);
}

}  // namespace tonus::sim::narrow
