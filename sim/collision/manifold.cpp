// Candidate buffer and the reduction of a manifold to at most four points.
#include <algorithm>
#include <cmath>
#include <limits>

#include "narrow.hpp"

namespace tonus::sim::narrow {

void Candidates::add(const Vec3& pos, const Vec3& normal, double dist) {
  // `!(dist <= margin)` also drops a NaN gap.
  if (!(dist <= margin_) || count_ == kCapacity) return;
  points_[count_] = {pos, normal, dist};
  ++count_;
}

double Candidates::min_dist() const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < count_; ++i) best = std::min(best, points_[i].dist_m);
  return best;
}

namespace {

// Index of the candidate maximising score(i) among those not yet chosen;
// ties go to the lower index so the result is deterministic.
template <typename Score>
std::size_t best_remaining(const Candidates& c, const std::array<bool, Candidates::kCapacity>& taken, Score score) {
  std::size_t best = c.size();
  double best_score = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (taken[i]) continue;
    const double s = score(i);
    if (best == c.size() || s > best_score) {
      best = i;
      best_score = s;
    }
  }
  return best;
}

}  // namespace

std::size_t reduce(const Candidates& c, std::size_t k, std::array<std::size_t, kMaxPointsPerPair>& idx) {
  k = std::min({k, c.size(), kMaxPointsPerPair});
  if (k == 0) return 0;
  std::array<bool, Candidates::kCapacity> taken{};
  std::size_t n = 0;
  const auto take = [&](std::size_t i) {
    taken[i] = true;
    idx[n++] = i;
  };

  // The deepest point always stays: it carries the pair's signed distance.
  take(best_remaining(c, taken, [&](std::size_t i) { return -c[i].dist_m; }));
  const Vec3 n0 = c[idx[0]].normal;
  // Positions projected on the contact plane: depth differences must not
  // count as spread (a box's top corners are not a wider base).
  const auto flat = [&](std::size_t i) -> Vec3 {
    const Vec3 p = c[i].pos - c[idx[0]].pos;
    return p - p.dot(n0) * n0;
  };
  if (n < k) take(best_remaining(c, taken, [&](std::size_t i) { return flat(i).squaredNorm(); }));
  if (n < k) {
    const Vec3 p1 = flat(idx[1]);
    take(best_remaining(c, taken, [&](std::size_t i) { return std::abs(p1.cross(flat(i)).dot(n0)); }));
  }
  if (n < k) {
    // Orient the triangle counter-clockwise about n0, then score each point by
    // the area it adds outside the triangle's edges.
    std::array<Vec3, 3> tri = {flat(idx[0]), flat(idx[1]), flat(idx[2])};
    if ((tri[1] - tri[0]).cross(tri[2] - tri[0]).dot(n0) < 0.0) std::swap(tri[1], tri[2]);
    take(best_remaining(c, taken, [&](std::size_t i) {
      const Vec3 q = flat(i);
      double added = 0.0;
      for (std::size_t e = 0; e < 3; ++e) {
        const Vec3& u = tri[e];
        const Vec3& v = tri[(e + 1) % 3];
        added += std::max(0.0, -(v - u).cross(q - u).dot(n0));
      }
      return added;
    }));
  }
  return n;
}

}  // namespace tonus::sim::narrow
