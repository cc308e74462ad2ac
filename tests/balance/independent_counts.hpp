// The independent estimator's verdict on a clip and on its corrected, written
// version: frames outside by more than 1 cm before and after, for the tests
// that judge a filter from outside (balance_crosscheck_tests); and where the
// frames still outside after sit against the estimator's own contact timing.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "independent/skeleton.hpp"
#include "independent/zmp_estimator.hpp"
#include "tonus/host/motion/clip.hpp"

namespace tonus::balance::test {

struct IndependentCounts {
  std::size_t before = 0, after = 0;
  std::size_t supported = 0;  // of the written clip
};

inline IndependentCounts independent_counts(const motion::Clip& original, const motion::Clip& written, double unit_m,
                                            std::size_t first_frame) {
  indep::Options io;
  io.metres_per_unit = unit_m;
  io.first_frame = first_frame;
  const indep::Estimate before = indep::estimate_zmp(original, io), after = indep::estimate_zmp(written, io);
  REQUIRE(before.ok());
  REQUIRE(after.ok());
  return {before.summary.outside, after.summary.outside, after.summary.supported};
}

// Where the independent estimator's frames outside after correction sit:
// within 0.1 s of one of its own contact changes (a heel or toe landing or
// lifting), against the share of all its supported frames that are; and how
// many stay outside when a foot point may land at up to 0.8 m/s (leave at
// 1.6) instead of 0.4 (0.8), a contact detection that calls a heel strike
// earlier.
struct ContactTiming {
  std::size_t outside = 0, outside_near_change = 0;
  std::size_t defined = 0, defined_near_change = 0;  // supported frames with the ZMP defined
  std::size_t outside_fast_landing = 0;
};

inline ContactTiming contact_timing(const motion::Clip& written, double unit_m, std::size_t first_frame) {
  indep::Options io;
  io.metres_per_unit = unit_m;
  io.first_frame = first_frame;
  const indep::Estimate e = indep::estimate_zmp(written, io);
  REQUIRE(e.ok());
  const auto reach = static_cast<std::size_t>(std::lround(0.1 / written.frame_time_s));
  const auto near_change = [&](std::size_t t) {
    for (std::size_t u = t > reach ? t - reach : 1; u <= t + reach && u < e.frames.size(); ++u) {
      if (e.frames[u].contact != e.frames[u - 1].contact) return true;
    }
    return false;
  };
  ContactTiming c;
  for (std::size_t t = 0; t < e.frames.size(); ++t) {
    const indep::FrameEstimate& f = e.frames[t];
    if (!f.analysed || !f.supported || !f.zmp_defined) continue;
    const bool near = near_change(t);
    ++c.defined;
    c.defined_near_change += near ? 1U : 0U;
    if (f.distance_m > io.tolerance_m) {
      ++c.outside;
      c.outside_near_change += near ? 1U : 0U;
    }
  }
  indep::Options fast = io;
  fast.contacts.enter_speed_mps = 0.8;
  fast.contacts.leave_speed_mps = 1.6;
  const indep::Estimate f = indep::estimate_zmp(written, fast);
  REQUIRE(f.ok());
  c.outside_fast_landing = f.summary.outside;
  return c;
}

// The original's and the written clip's sites from `first_frame` on, by the
// independent estimator's skeleton (mapped on the original) and kinematics.
inline std::pair<std::vector<indep::Sites>, std::vector<indep::Sites>> site_pair(const motion::Clip& original,
                                                                                 const motion::Clip& written,
                                                                                 double unit_m,
                                                                                 std::size_t first_frame) {
  const indep::SkeletonMap map = indep::map_skeleton(original);
  REQUIRE_MESSAGE(map.ok(), map.error);
  std::pair<std::vector<indep::Sites>, std::vector<indep::Sites>> sites{
      indep::site_positions(original, map, unit_m, first_frame),
      indep::site_positions(written, map, unit_m, first_frame)};
  REQUIRE(sites.first.size() == sites.second.size());
  return sites;
}

// How smoothly a correction moves the pelvis up and down, read from the
// written file by the independent estimator's own skeleton and forward
// kinematics: the midpoint of the hip joints (the filters' pivot, which lean
// and yaw leave in place) minus the original's, its second difference over
// dt^2 from `first_frame` on: the vertical acceleration the correction adds.
struct PelvisHeightChange {
  double max_m = 0.0;           // the largest lowering or raising
  double max_accel_mps2 = 0.0;  // its largest acceleration
  double p99_accel_mps2 = 0.0;  // and the 99th percentile
};

inline PelvisHeightChange pelvis_height_change(const motion::Clip& original, const motion::Clip& written, double unit_m,
                                               std::size_t first_frame) {
  const auto [a, b] = site_pair(original, written, unit_m, first_frame);
  std::vector<double> dz(a.size());
  PelvisHeightChange c;
  for (std::size_t t = 0; t < a.size(); ++t) {
    const auto mid = [](const indep::Sites& s) { return 0.5 * (s[indep::left_hip].z() + s[indep::right_hip].z()); };
    dz[t] = mid(b[t]) - mid(a[t]);
    c.max_m = std::max(c.max_m, std::abs(dz[t]));
  }
  std::vector<double> accel;
  const double dt2 = original.frame_time_s * original.frame_time_s;
  for (std::size_t t = 1; t + 1 < dz.size(); ++t) accel.push_back(std::abs(dz[t + 1] - 2.0 * dz[t] + dz[t - 1]) / dt2);
  if (accel.empty()) return c;
  std::sort(accel.begin(), accel.end());
  c.max_accel_mps2 = accel.back();
  c.p99_accel_mps2 = accel[static_cast<std::size_t>(0.99 * static_cast<double>(accel.size() - 1))];
  return c;
}

// Whether a correction adds jitter: the horizontal jerk (third difference
// over dt^3) of the pelvis (the hip joints' midpoint) and of the neck, in the
// original and in the written file, by the independent estimator's own
// skeleton and forward kinematics, unsmoothed: RMS and 99th percentile.
struct HorizontalJerk {
  double rms_before_mps3 = 0.0, rms_after_mps3 = 0.0;
  double p99_before_mps3 = 0.0, p99_after_mps3 = 0.0;
};
struct SiteJerks {
  HorizontalJerk pelvis, neck;
};

inline SiteJerks horizontal_jerks(const motion::Clip& original, const motion::Clip& written, double unit_m,
                                  std::size_t first_frame) {
  const auto [a, b] = site_pair(original, written, unit_m, first_frame);
  const double dt3 = std::pow(original.frame_time_s, 3);
  const auto jerk = [&](const std::vector<indep::Sites>& s, auto&& point, double& rms, double& p99) {
    std::vector<double> j;
    for (std::size_t t = 3; t < s.size(); ++t) {
      const Eigen::Vector3d d = point(s[t]) - 3.0 * point(s[t - 1]) + 3.0 * point(s[t - 2]) - point(s[t - 3]);
      j.push_back(d.head<2>().norm() / dt3);
    }
    if (j.empty()) return;
    double sum = 0.0;
    for (const double v : j) sum += v * v;
    rms = std::sqrt(sum / static_cast<double>(j.size()));
    std::sort(j.begin(), j.end());
    p99 = j[static_cast<std::size_t>(0.99 * static_cast<double>(j.size() - 1))];
  };
  const auto pelvis = [](const indep::Sites& s) -> Eigen::Vector3d {
    return 0.5 * (s[indep::left_hip] + s[indep::right_hip]);
  };
  const auto neck = [](const indep::Sites& s) -> Eigen::Vector3d { return s[indep::neck]; };
  SiteJerks j;
  jerk(a, pelvis, j.pelvis.rms_before_mps3, j.pelvis.p99_before_mps3);
  jerk(b, pelvis, j.pelvis.rms_after_mps3, j.pelvis.p99_after_mps3);
  jerk(a, neck, j.neck.rms_before_mps3, j.neck.p99_before_mps3);
  jerk(b, neck, j.neck.rms_after_mps3, j.neck.p99_after_mps3);
  return j;
}

}  // namespace tonus::balance::test
