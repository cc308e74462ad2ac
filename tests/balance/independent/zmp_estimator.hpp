// An independent zero moment point (ZMP) estimator for the tests, sharing no
// code with host/balance, host/derivatives or sim/ (only the BVH reader and
// forward kinematics of host/motion, and Eigen): its own joint names, frame
// conversion, de Leva mass model, Butterworth smoothing with central
// differences, foot contacts and support polygon. It checks the balance
// filter's results by a second opinion built another way (issue 14).
//
// Method, per frame t of a BVH clip:
// - joint centres by forward kinematics, converted to Z up and metres
//   (skeleton.hpp); the unit is the caller's (no guessing);
// - de Leva's 14 segment centres of mass (body.hpp), each coordinate smoothed
//   by a 2nd-order Butterworth low-pass run forward and backward
//   (butterworth.hpp), accelerations by central differences (differences.hpp);
// - the particle-model ZMP over a ground plane at height z0:
//   p_x = sum m_i [(zdd_i + g) x_i - xdd_i (z_i - z0)] / sum m_i (zdd_i + g),
//   likewise p_y; undefined when the vertical force sum m_i (zdd_i + g) is
//   under 10 % of the weight;
// - a heel and a toe point per foot, each down when low and slow
//   (contacts.hpp); the support polygon is the convex hull of the points
//   down widened by the sole's half width (hull.hpp). No point down: the
//   frame is airborne, neither inside nor outside.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "independent/contacts.hpp"
#include "tonus/host/motion/clip.hpp"

namespace tonus::indep {

inline constexpr double kCmuUnit_m = 0.056444;  // CMU's FAQ: (1 / 0.45) * 2.54 / 100
inline constexpr double kCentimetre_m = 0.01;   // Bandai Namco's clips

struct Options {
  double metres_per_unit = 0.0;  // required: kCmuUnit_m, kCentimetre_m, ...
  std::size_t first_frame = 0;   // 1 skips the T-pose frame the CMU conversions start with
  double cutoff_hz = 6.0;
  double gravity_mps2 = 9.81;
  // The ground's height in the internal frame (the file's Y times the unit).
  // Without it, the lowest foot point's resting height (ContactOptions) at
  // each frame: the toe joints' height, a few cm above the floor (4.2 cm on
  // the Bandai Namco clips). The ZMP moves by that error times the horizontal
  // acceleration over g: 0.4-1.2 cm on average on the shared clips against a
  // ground at the file's y = 0, and 0-12 % more frames outside.
  std::optional<double> ground_height_m;
  double tolerance_m = 0.01;     // "outside" means farther out than this
  double min_force_ratio = 0.1;  // of the weight, for a defined ZMP
  ContactOptions contacts;
};

// Foot points, in the order of FrameEstimate::contact.
enum FootPoint : std::size_t { left_heel, left_toes, right_heel, right_toes, kFootPointCount };

struct FrameEstimate {
  bool analysed = false;                          // at or after first_frame
  bool supported = false;                         // some foot point down
  bool zmp_defined = false;                       // enough vertical force
  Eigen::Vector2d zmp = Eigen::Vector2d::Zero();  // meaningful when zmp_defined
  double distance_m = 0.0;                        // to the support polygon, > 0 outside; 0 unless supported and defined
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // whole body, smoothed
  double ground_m = 0.0;                          // the z0 the ZMP is taken on
  std::array<bool, kFootPointCount> contact{};
  std::array<double, kFootPointCount> clearance_m{};  // height over the point's resting height
  std::array<double, kFootPointCount> speed_mps{};
};

struct Summary {
  std::size_t frames = 0;  // analysed
  std::size_t supported = 0;
  std::size_t airborne = 0;
  std::size_t undefined = 0;   // supported, but the ZMP undefined
  std::size_t outside = 0;     // supported, defined, distance over the tolerance
  double max_outside_m = 0.0;  // largest distance of a supported frame, 0 if all inside
};

struct Estimate {
  std::string error;                  // why there is no estimate
  std::vector<FrameEstimate> frames;  // one per clip frame
  Summary summary;
  double stature_m = 0.0;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Never throws on bad input: an unmapped skeleton, non-finite values, a bad
// unit, frame time or cutoff, or first_frame past the end come back as error.
[[nodiscard]] Estimate estimate_zmp(const motion::Clip& clip, const Options& options);

}  // namespace tonus::indep
