// `tonus ctl` (tools/tonus/ctl_command.*), wired exactly as tools/tonus/main.cpp
// wires it, against a server with a fake handler: exit codes 0 / 1 / 2.
#include <doctest/doctest.h>

#include <CLI/CLI.hpp>

#include <string>

#include "control_fixtures.hpp"
#include "ctl_command.hpp"

namespace tc = tonus::control;
using tc::testing::RunningServer;

namespace {

// Parses `args` as `tonus ARGS` and runs ctl; -1000 - CLI11's code on a parse error.
int run_tonus(const std::string& args, tonus::tools::CtlOptions* seen = nullptr) {
  CLI::App app{"tonus"};
  app.require_subcommand(1);
  tonus::tools::CtlOptions ctl;
  CLI::App* ctl_cmd = tonus::tools::add_ctl_command(app, ctl);
  try {
    app.parse(args, false);
  } catch (const CLI::ParseError& e) {
    return -1000 - e.get_exit_code();
  }
  if (seen != nullptr) *seen = ctl;
  REQUIRE(ctl_cmd->parsed());
  return tonus::tools::run_ctl_command(ctl);
}

}  // namespace

TEST_CASE("tonus ctl: every action, exit 0 on 2xx") {
  RunningServer s;
  const std::string p = " --port " + std::to_string(s.port());
  CHECK(run_tonus("ctl" + p + " status") == 0);
  CHECK(run_tonus("ctl status" + p) == 0);  // options after the action too
  CHECK(run_tonus("ctl" + p + " gift cube --bone LeftHand --mass-kg 2 --size-m 0.1 --height-m 0.5 --lifetime-s 30") ==
        0);
  REQUIRE(s.handler.last_gift);
  CHECK(s.handler.last_gift->kind == tc::GiftKind::cube);
  CHECK(s.handler.last_gift->bone == tonus::sim::Bone::LeftHand);
  CHECK(s.handler.last_gift->mass_kg == 2.0);
  CHECK(s.handler.last_gift->size_m == 0.1);
  CHECK(s.handler.last_gift->height_m == 0.5);
  CHECK(s.handler.last_gift->lifetime_s == 30.0);
  CHECK_FALSE(s.handler.last_gift->speed_mps);
  CHECK(run_tonus("ctl" + p + " gift ball --speed-mps 12") == 0);
  CHECK(s.handler.last_gift->kind == tc::GiftKind::ball);
  CHECK(s.handler.last_gift->speed_mps == 12.0);
  CHECK_FALSE(s.handler.last_gift->bone);
  CHECK(run_tonus("ctl" + p + " clear") == 0);
  CHECK(run_tonus("ctl" + p + " stiffness 0.1 0.2 0.3 1") == 0);
  REQUIRE(s.handler.last_levels);
  CHECK(*s.handler.last_levels == tc::Levels{0.1, 0.2, 0.3, 1.0});
  CHECK(run_tonus("ctl" + p + " stiffness release") == 0);
  CHECK_FALSE(s.handler.last_levels->has_value());
  CHECK(run_tonus("ctl" + p + " calibrate rest") == 0);
  CHECK(s.handler.last_calibration == tc::CalibrationCommand::rest);
  CHECK(run_tonus("ctl" + p + " calibrate mvc") == 0);
  CHECK(s.handler.last_calibration == tc::CalibrationCommand::mvc);
}

TEST_CASE("tonus ctl: exit 1 on an error reply") {
  RunningServer s;
  const std::string p = " --port " + std::to_string(s.port());
  CHECK(run_tonus("ctl" + p + " stiffness 2 0 0 0") == 1);        // the server's range check
  CHECK(run_tonus("ctl" + p + " gift ball --mass-kg 100") == 1);  // ditto
  CHECK(run_tonus("ctl" + p + " gift cube --speed-mps 3") == 1);  // a cube is not thrown
  CHECK(run_tonus("ctl" + p + " calibrate abort") == 1);          // the handler's 409
  CHECK(s.handler.calls() == std::vector<std::string>{"calibrate"});
}

TEST_CASE("tonus ctl: exit 2 when the daemon cannot be reached") {
  const int port = tc::testing::free_port();
  CHECK(run_tonus("ctl --port " + std::to_string(port) + " --timeout 1 status") == 2);
}

TEST_CASE("tonus ctl: usage errors are parse errors") {
  CHECK(run_tonus("ctl") <= -1000);
  CHECK(run_tonus("ctl gift pyramid") <= -1000);
  CHECK(run_tonus("ctl gift ball --bone Tail") <= -1000);
  CHECK(run_tonus("ctl stiffness 1 2") <= -1000);
  CHECK(run_tonus("ctl stiffness a b c d") <= -1000);
  CHECK(run_tonus("ctl stiffness") <= -1000);
  CHECK(run_tonus("ctl calibrate warmup") <= -1000);
  CHECK(run_tonus("ctl --port 0 status") <= -1000);
}
