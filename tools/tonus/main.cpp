#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <exception>

#include "physics_demo.hpp"
#include "protocol_demo.hpp"

namespace {

int run(int argc, char** argv) {
  CLI::App app{"tonus: EMG-driven avatar stiffness (band protocol, physics, balance)"};
  app.require_subcommand(1);

  tonus::tools::DemoOptions demo;
  CLI::App* demo_cmd = app.add_subcommand(
      "demo", "Simulate a band stream, send it over HID and CAN with loss, decode it back, print a summary");
  demo_cmd->add_option("--seconds", demo.seconds, "Stream length in seconds")->check(CLI::Range(0.01, 3600.0));
  demo_cmd->add_option("--rate", demo.report_rate_hz, "Report rate in Hz")->check(CLI::Range(1U, 1000U));
  demo_cmd->add_option("--loss", demo.loss, "Drop probability per report / frame")->check(CLI::Range(0.0, 0.5));
  demo_cmd->add_option("--duplication", demo.duplication, "Duplication probability per report")
      ->check(CLI::Range(0.0, 0.5));
  demo_cmd->add_option("--reorder", demo.reorder, "Probability two neighbouring reports swap")
      ->check(CLI::Range(0.0, 0.5));
  demo_cmd->add_option("--seed", demo.seed, "Random seed (runs are reproducible)");
  demo_cmd->add_option("--can-node", demo.can_node, "CAN node id")->check(CLI::Range(0, 31));
  demo_cmd->add_option("--candump", demo.candump_path, "Write the CAN traffic as a candump log");

  tonus::tools::PhysicsDemoOptions physics;
  CLI::App* physics_cmd = app.add_subcommand(
      "physics", "Stand the humanoid on the ground, drop a cube on its hand, throw a ball at it, print a summary");
  physics_cmd->add_option("--seconds", physics.seconds, "Simulated time")->check(CLI::Range(0.01, 600.0));
  physics_cmd->add_option("--height", physics.height_m, "Body height, m")->check(CLI::Range(0.5, 3.0));
  physics_cmd->add_option("--mass", physics.mass_kg, "Body mass, kg")->check(CLI::Range(5.0, 500.0));
  physics_cmd->add_option("--hold-hz", physics.hold_hz, "Natural frequency of the pose-holding drives, Hz")
      ->check(CLI::Range(0.1, 200.0));
  physics_cmd->add_option("--ball-speed", physics.ball_speed_mps, "Speed of the ball thrown at 1 s, m/s (0: none)")
      ->check(CLI::Range(0.0, 30.0));
  physics_cmd->add_option("--mjcf", physics.mjcf_path, "Write the scene as MuJoCo MJCF to this file");

  CLI11_PARSE(app, argc, argv);
  if (demo_cmd->parsed()) return tonus::tools::run_protocol_demo(demo);
  if (physics_cmd->parsed()) return tonus::tools::run_physics_demo(physics);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Errors are reported, never escape as an abort: a tool run by scripts must exit with a code.
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    fmt::print(stderr, "tonus: error: {}\n", e.what());
  } catch (...) {
    fmt::print(stderr, "tonus: unknown error\n");
  }
  return 1;
}
