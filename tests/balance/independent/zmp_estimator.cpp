#include "independent/zmp_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "independent/body.hpp"
#include "independent/butterworth.hpp"
#include "independent/differences.hpp"
#include "independent/hull.hpp"
#include "independent/skeleton.hpp"

namespace tonus::indep {

namespace {

// Each coordinate of a point over the analysed frames.
struct Track {
  std::array<std::vector<double>, 3> raw, smooth, rate;  // rate: velocity or acceleration
};

std::string check(const motion::Clip& clip, const Options& o) {
  if (!std::isfinite(o.metres_per_unit) || o.metres_per_unit <= 0.0) return "the unit (metres per unit) is not set";
  if (!std::isfinite(clip.frame_time_s) || clip.frame_time_s <= 0.0) return "the frame time is not positive";
  if (o.first_frame >= clip.frame_count) return "first_frame is past the last frame";
  if (!(o.cutoff_hz > 0.0 && o.cutoff_hz < 0.5 / clip.frame_time_s)) return "the cutoff is not below the Nyquist rate";
  if (clip.values.size() != clip.frame_count * clip.channel_count())
    return "the frames' values do not fit the channels";
  // One NaN would spread through the recursive filter to the whole clip.
  const auto bad = std::ranges::find_if(clip.values, [](double v) { return !std::isfinite(v); });
  if (bad != clip.values.end()) {
    const auto at = static_cast<std::size_t>(bad - clip.values.begin());
    return "frame " + std::to_string(at / clip.channel_count()) + " has a value that is not a finite number";
  }
  return {};
}

void smooth(Track& track, const Biquad& filter, double dt, bool acceleration) {
  for (std::size_t a = 0; a < 3; ++a) {
    track.smooth[a] = filtfilt(filter, track.raw[a]);
    track.rate[a] = acceleration ? second_derivative(track.smooth[a], dt) : first_derivative(track.smooth[a], dt);
  }
}

Vec3 at(const std::array<std::vector<double>, 3>& v, std::size_t t) { return {v[0][t], v[1][t], v[2][t]}; }

// Segment centres of mass with their accelerations, foot points with their
// velocities, over the analysed frames.
struct Tracks {
  std::array<Track, kSegmentCount> segments;
  std::array<Track, kFootPointCount> points;
};

Tracks track(const std::vector<Sites>& sites, const Proportions& body, double dt, double cutoff_hz) {
  Tracks tracks;
  std::array<Eigen::Vector2d, 2> axis{Eigen::Vector2d::UnitX(), Eigen::Vector2d::UnitX()};
  for (const Sites& s : sites) {
    const Foot left = place_foot(s, 0, body, axis[0]);
    const Foot right = place_foot(s, kRightOffset, body, axis[1]);
    axis = {left.axis, right.axis};
    const std::array<Vec3, kSegmentCount> centres = segment_centres(s, left, right, body);
    const std::array<Vec3, kFootPointCount> feet{left.heel_point, left.toe_point, right.heel_point, right.toe_point};
    for (std::size_t a = 0; a < 3; ++a) {
      const auto axis_index = static_cast<Eigen::Index>(a);
      for (std::size_t i = 0; i < kSegmentCount; ++i) tracks.segments[i].raw[a].push_back(centres[i][axis_index]);
      for (std::size_t i = 0; i < kFootPointCount; ++i) tracks.points[i].raw[a].push_back(feet[i][axis_index]);
    }
  }
  const Biquad filter = butterworth_lowpass(cutoff_hz, 1.0 / dt);
  for (Track& t : tracks.segments) smooth(t, filter, dt, true);
  for (Track& t : tracks.points) smooth(t, filter, dt, false);
  return tracks;
}

struct Contacts {
  std::array<std::vector<bool>, kFootPointCount> down;
  std::array<std::vector<double>, kFootPointCount> clearance, speed;
  std::vector<double> ground;
};

Contacts find_contacts(const Tracks& tracks, const Options& o, double dt) {
  const std::size_t n = tracks.points[0].raw[2].size();
  const auto half_window = static_cast<std::size_t>(std::lround(0.5 * o.contacts.window_s / dt));
  Contacts c;
  c.ground.assign(n, o.ground_height_m.value_or(std::numeric_limits<double>::infinity()));
  for (std::size_t i = 0; i < kFootPointCount; ++i) {
    const std::vector<double>& height = tracks.points[i].raw[2];
    const std::vector<double> rest = rolling_percentile(height, half_window, o.contacts.rest_percentile);
    for (std::size_t t = 0; t < n; ++t) {
      c.speed[i].push_back(at(tracks.points[i].rate, t).norm());
      c.clearance[i].push_back(height[t] - rest[t]);
      if (!o.ground_height_m) c.ground[t] = std::min(c.ground[t], rest[t]);
    }
    c.down[i] = detect_contact(height, rest, c.speed[i], o.contacts);
  }
  return c;
}

// The particle-model ZMP and the centre of mass at analysed frame t.
void zero_moment_point(FrameEstimate& f, const Tracks& tracks, std::size_t t, const Options& o) {
  const double g = o.gravity_mps2;
  double force = 0.0;  // vertical, per unit body mass
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const double m = de_leva_male()[i].mass_fraction;
    const Vec3 p = at(tracks.segments[i].smooth, t), acc = at(tracks.segments[i].rate, t);
    f.com += m * p;
    force += m * (acc.z() + g);
    moment += m * ((acc.z() + g) * p.head<2>() - acc.head<2>() * (p.z() - f.ground_m));
  }
  f.zmp_defined = force >= o.min_force_ratio * g;
  if (f.zmp_defined) f.zmp = moment / force;
}

}  // namespace

Estimate estimate_zmp(const motion::Clip& clip, const Options& o) {
  Estimate e;
  e.error = check(clip, o);
  if (!e.ok()) return e;
  const SkeletonMap map = map_skeleton(clip);
  if (!map.ok()) {
    e.error = map.error;
    return e;
  }
  const std::vector<Sites> sites = site_positions(clip, map, o.metres_per_unit, o.first_frame);
  if (sites.empty()) {
    e.error = "forward kinematics failed";
    return e;
  }
  const Proportions body = proportions(sites.front());
  if (!std::isfinite(body.stature_m) || body.stature_m < 1e-3) {
    e.error = "the legs have no length";
    return e;
  }
  e.stature_m = body.stature_m;
  const Tracks tracks = track(sites, body, clip.frame_time_s, o.cutoff_hz);
  const Contacts contacts = find_contacts(tracks, o, clip.frame_time_s);

  e.frames.resize(clip.frame_count);
  Summary& sum = e.summary;
  for (std::size_t t = 0; t < sites.size(); ++t) {
    FrameEstimate& f = e.frames[o.first_frame + t];
    f.analysed = true;
    f.ground_m = contacts.ground[t];
    zero_moment_point(f, tracks, t, o);
    std::vector<Point2> support;
    for (std::size_t i = 0; i < kFootPointCount; ++i) {
      f.contact[i] = contacts.down[i][t];
      f.clearance_m[i] = contacts.clearance[i][t];
      f.speed_mps[i] = contacts.speed[i][t];
      if (f.contact[i]) support.push_back(at(tracks.points[i].smooth, t).head<2>());
    }
    f.supported = !support.empty();
    ++sum.frames;
    if (!f.supported) {
      ++sum.airborne;
      continue;
    }
    ++sum.supported;
    if (!f.zmp_defined) {
      ++sum.undefined;
      continue;
    }
    // The hull of the points down, widened by the sole's half width.
    f.distance_m = signed_distance(convex_hull(support), f.zmp) - body.sole_half_width_m;
    sum.max_outside_m = std::max(sum.max_outside_m, f.distance_m);
    if (f.distance_m > o.tolerance_m) ++sum.outside;
  }
  return e;
}

}  // namespace tonus::indep
