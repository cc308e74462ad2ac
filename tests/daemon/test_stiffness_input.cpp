// Band staleness: held while reports come, eased to the safe default within
// 100 ms of going stale, taken over again by the next report.
#include <doctest/doctest.h>

#include <limits>

#include "tonus/host/daemon/stiffness_input.hpp"

using namespace tonus::daemon;

TEST_CASE("stiffness: the safe default until the first report, then the report's levels") {
  StiffnessInputConfig c;
  StiffnessInput s(c);
  CHECK(s.at(0) == c.safe_default);
  CHECK_FALSE(s.live(0));
  s.on_report(1'000'000, {0.9, 0.8, 0.7, 1.5});
  CHECK(s.at(1'000'000)[0] == 0.9);
  CHECK(s.at(1'000'000)[3] == 1.0);  // clamped
  CHECK(s.live(1'050'000));
}

TEST_CASE("stiffness: 100 ms without a report eases to the safe default within the next 100 ms, a report resumes") {
  StiffnessInputConfig c;
  StiffnessInput s(c);
  const Levels high{0.9, 0.9, 0.9, 0.9};
  s.on_report(0, high);
  CHECK(s.at(100'000) == high);  // still live at exactly 100 ms
  CHECK(s.live(100'000));
  CHECK_FALSE(s.live(100'001));
  const Levels mid = s.at(145'000);  // halfway through the 90 ms ease
  CHECK(mid[0] == doctest::Approx(0.9 + 0.5 * (0.3 - 0.9)));
  CHECK(s.at(190'000)[0] == doctest::Approx(0.3));
  CHECK(s.at(200'000) == c.safe_default);
  CHECK(s.at(5'000'000) == c.safe_default);
  s.on_report(5'000'000, {0.6, 0.6, 0.6, 0.6});
  CHECK(s.at(5'000'001)[0] == 0.6);
}

TEST_CASE("stiffness: non-finite levels keep the last value, bad configs are named") {
  StiffnessInput s(StiffnessInputConfig{});
  s.on_report(0, {0.7, 0.7, 0.7, 0.7});
  s.on_report(1000, {std::nan(""), 0.2, std::numeric_limits<double>::infinity(), 0.1});
  CHECK(s.at(1000)[0] == 0.7);
  CHECK(s.at(1000)[1] == 0.2);
  CHECK(s.at(1000)[2] == 0.7);
  StiffnessInputConfig bad;
  bad.safe_default[2] = 1.5;
  CHECK(validate(bad).find("band.safe_stiffness = 1.5") != std::string::npos);
  bad = {};
  bad.stale_after_s = 0.0;
  CHECK(validate(bad).find("band.stale_after_ms") != std::string::npos);
}
