#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <exception>

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

  CLI11_PARSE(app, argc, argv);
  if (demo_cmd->parsed()) return tonus::tools::run_protocol_demo(demo);
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
