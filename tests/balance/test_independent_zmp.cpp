// The independent ZMP estimator on synthetic bodies against closed forms (a
// still pose, a cart-table motion, a ballistic hop), its joint names and
// units, and bad input.
#include <doctest/doctest.h>

#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>

#include "independent/body.hpp"
#include "independent/zmp_estimator.hpp"
#include "synthetic_body.hpp"

using namespace tonus;
using balance::test::Names;
using balance::test::synthetic_body;

namespace {

constexpr double kG = 9.81;

indep::Options centimetres() {
  indep::Options o;
  o.metres_per_unit = indep::kCentimetre_m;
  return o;
}

motion::Clip standing(std::size_t frames = 120, Names names = Names::cmu) {
  return synthetic_body(frames, names, [](double) { return Eigen::Vector3d::Zero(); });
}

indep::Estimate estimate(const motion::Clip& clip, const indep::Options& o) {
  indep::Estimate e = indep::estimate_zmp(clip, o);
  REQUIRE_MESSAGE(e.ok(), e.error);
  return e;
}

}  // namespace

TEST_CASE(
    "independent ZMP: de Leva's masses add up to the body, and the centre of mass stands at 55-58 % of the stature") {
  double total = 0.0;
  for (const auto& s : indep::de_leva_male()) total += s.mass_fraction;
  CHECK(total == doctest::Approx(1.0).epsilon(1e-12));
  const indep::Estimate e = estimate(standing(), centimetres());
  // Legs 84 cm: de Leva's thigh and shank are 422.2 + 440.3 mm of 1741.
  CHECK(e.stature_m == doctest::Approx(0.84 * 1741.0 / (422.2 + 440.3)).epsilon(1e-9));
  const Eigen::Vector3d com = e.frames[60].com;
  CHECK(com.z() / e.stature_m > 0.55);
  CHECK(com.z() / e.stature_m < 0.58);
  CHECK(std::abs(com.x()) < 1e-12);  // left and right mirror each other
}

TEST_CASE(
    "independent ZMP: a still pose puts the ZMP under the centre of mass, inside both feet, at any ground height") {
  const motion::Clip clip = standing();
  for (const std::optional<double> ground : {std::optional<double>{}, std::optional(0.0), std::optional(-0.3)}) {
    indep::Options o = centimetres();
    o.ground_height_m = ground;
    const indep::Estimate e = estimate(clip, o);
    CHECK(e.summary.frames == 120);
    CHECK(e.summary.supported == 120);
    CHECK(e.summary.outside == 0);
    for (const indep::FrameEstimate& f : e.frames) {
      REQUIRE(f.zmp_defined);
      CHECK((f.zmp - f.com.head<2>()).norm() < 1e-9);
      CHECK(f.distance_m < -0.05);  // the centre of mass is well between the feet
      CHECK(f.contact == std::array<bool, 4>{true, true, true, true});
    }
  }
  // The ground found is the toe points' height: the toe joints, 2 cm up.
  CHECK(estimate(clip, centimetres()).frames[10].ground_m == doctest::Approx(0.02));
}

TEST_CASE("independent ZMP: a cart-table (linear inverted pendulum) motion gives p = x - z_c xdd / g") {
  // The whole body sways forward and back as one: x(t) = A sin(w t) along the
  // file's +z (the internal -y); every segment has the same acceleration.
  const double a = 0.05, w = 2.0 * std::numbers::pi * 0.8;
  const motion::Clip clip =
      synthetic_body(480, Names::cmu, [&](double t) { return Eigen::Vector3d(0, 0, 100.0 * a * std::sin(w * t)); });
  indep::Options o = centimetres();
  o.ground_height_m = 0.0;
  const indep::Estimate still = estimate(standing(), o);
  const double y0 = still.frames[0].com.y(), zc = still.frames[0].com.z();
  const indep::Estimate e = estimate(clip, o);
  double worst = 0.0, worst_end = 0.0;
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    const double t = static_cast<double>(f) * clip.frame_time_s;
    const double y = y0 - a * std::sin(w * t), ydd = a * w * w * std::sin(w * t);
    const double error = std::abs(e.frames[f].zmp.y() - (y - zc * ydd / kG));
    (t >= 0.5 && t <= 3.5 ? worst : worst_end) = std::max(t >= 0.5 && t <= 3.5 ? worst : worst_end, error);
    CHECK(std::abs(e.frames[f].zmp.x()) < 1e-9);
  }
  MESSAGE("cart-table: largest ZMP error " << worst << " m from 0.5 s to 3.5 s, " << worst_end
                                           << " m in the first and last 0.5 s (ZMP swing " << a * (1 + zc * w * w / kG)
                                           << " m)");
  // Butterworth's gain at 0.8 Hz (1 - 1.6e-4) and the central difference's
  // (1 - (w dt)^2 / 12) leave well under a millimetre.
  CHECK(worst < 1e-3);
}

TEST_CASE("independent ZMP: a ballistic hop is airborne and has no ZMP at the top") {
  const double v0 = 1.5, flight = 2.0 * v0 / kG, takeoff = 0.8;  // m/s, s, s
  const motion::Clip clip = synthetic_body(240, Names::cmu, [&](double t) {
    const double tau = t - takeoff;
    return Eigen::Vector3d(0, tau > 0.0 && tau < flight ? 100.0 * (v0 * tau - 0.5 * kG * tau * tau) : 0.0, 0);
  });
  const indep::Estimate e = estimate(clip, centimetres());
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    const double t = static_cast<double>(f) * clip.frame_time_s;
    const indep::FrameEstimate& fr = e.frames[f];
    if (std::abs(t - takeoff - 0.5 * flight) < 0.1) CHECK_MESSAGE(!fr.supported, "frame " << f);
    if (std::abs(t - takeoff - 0.5 * flight) < 0.03) CHECK_MESSAGE(!fr.zmp_defined, "frame " << f);
    if (t < takeoff - 0.1 || t > takeoff + flight + 0.1) CHECK_MESSAGE(fr.supported, "frame " << f);
  }
  CHECK(e.summary.airborne > 20);
  CHECK(e.summary.airborne < 45);
  CHECK(e.summary.airborne + e.summary.supported == e.summary.frames);
}

TEST_CASE("independent ZMP: CMU and Bandai Namco names, in any case, and any unit give the same estimate") {
  const std::function<Eigen::Vector3d(double)> sway = [](double t) {
    return Eigen::Vector3d(3 * std::sin(4 * t), 0, 20 * t);
  };
  const indep::Estimate cmu = estimate(synthetic_body(200, Names::cmu, sway), centimetres());
  motion::Clip bandai = synthetic_body(200, Names::bandai, sway);
  for (motion::Joint& j : bandai.joints) {
    for (char& c : j.name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  const indep::Estimate other = estimate(bandai, centimetres());
  // The same body in metres.
  motion::Clip metres = synthetic_body(200, Names::cmu, sway);
  for (motion::Joint& j : metres.joints) j.offset /= 100.0;
  const std::size_t columns = metres.channel_count();
  for (std::size_t k = 0; k < metres.values.size(); ++k) {
    if (k % columns < 3) metres.values[k] /= 100.0;  // the root's position channels
  }
  indep::Options o;
  o.metres_per_unit = 1.0;
  const indep::Estimate in_metres = estimate(metres, o);
  for (std::size_t f = 0; f < 200; ++f) {
    CHECK((cmu.frames[f].zmp - other.frames[f].zmp).norm() == 0.0);
    CHECK(cmu.frames[f].distance_m == other.frames[f].distance_m);
    CHECK((cmu.frames[f].zmp - in_metres.frames[f].zmp).norm() < 1e-12);
  }
  CHECK(cmu.summary.supported == in_metres.summary.supported);
}

TEST_CASE("independent ZMP: a T-pose frame can be skipped") {
  indep::Options o = centimetres();
  o.first_frame = 1;
  const indep::Estimate e = estimate(standing(), o);
  CHECK(e.frames.size() == 120);
  CHECK_FALSE(e.frames[0].analysed);
  CHECK(e.frames[1].analysed);
  CHECK(e.summary.frames == 119);
}

TEST_CASE("independent ZMP: bad input is an error, never a crash") {
  const auto error = [](const motion::Clip& clip, const indep::Options& o) {
    const indep::Estimate e = indep::estimate_zmp(clip, o);
    CHECK_FALSE(e.ok());
    CHECK(e.frames.empty());
    return e.error;
  };
  motion::Clip unknown = standing();
  unknown.joints[1].name = "Thigh.L";      // was LeftUpLeg
  unknown.joints[15].name = "wrist_left";  // was LeftHand
  const std::string why = error(unknown, centimetres());
  MESSAGE(why);
  CHECK(why.find("left hip") != std::string::npos);
  CHECK(why.find("left wrist") != std::string::npos);
  CHECK(why.find("right") == std::string::npos);
  error(motion::Clip{}, centimetres());
  motion::Clip nan = standing();
  nan.values[5 * nan.channel_count() + 7] = std::numeric_limits<double>::quiet_NaN();
  CHECK(error(nan, centimetres()).find("frame 5") != std::string::npos);
  nan.values[5 * nan.channel_count() + 7] = std::numeric_limits<double>::infinity();
  error(nan, centimetres());
  error(standing(), indep::Options{});  // no unit
  indep::Options o = centimetres();
  o.cutoff_hz = 60.0;  // the Nyquist rate at 120 Hz
  error(standing(), o);
  o = centimetres();
  o.first_frame = 120;
  error(standing(), o);
  motion::Clip flat = standing();
  for (motion::Joint& j : flat.joints) j.offset.setZero();
  error(flat, centimetres());  // no legs to scale the body by
  motion::Clip short_values = standing();
  short_values.values.pop_back();
  error(short_values, centimetres());
  // Clips too short to filter still give an answer.
  for (const std::size_t frames : std::array<std::size_t, 4>{1, 2, 3, 4}) {
    const indep::Estimate e = estimate(standing(frames), centimetres());
    CHECK(e.summary.frames == frames);
    CHECK(e.frames.back().zmp.allFinite());
  }
}
