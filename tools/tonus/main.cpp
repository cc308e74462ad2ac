#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <exception>

#include "ctl_command.hpp"
#include "experiment_command.hpp"
#include "ik_command.hpp"
#include "physics_demo.hpp"
#include "protocol_demo.hpp"
#include "zmp_command.hpp"

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

  tonus::tools::ZmpCommandOptions zmp;
  CLI::App* zmp_cmd = app.add_subcommand(
      "zmp", "Analyse a BVH clip's zero moment point and correct its balance (waist rotation, feet kept)");
  zmp_cmd->add_option("input", zmp.input, "Input BVH file")->required();
  zmp_cmd->add_option("-o,--output", zmp.output, "Write the corrected BVH here");
  zmp_cmd->add_option("--csv", zmp.csv, "Write the ZMP before/after per frame as CSV");
  zmp_cmd->add_option("--json", zmp.json, "Write a machine-readable report");
  zmp_cmd->add_option("--svg", zmp.svg, "Plot the ZMP trajectories with the support intervals shaded");
  zmp_cmd->add_option("--mapping", zmp.mapping, "Joint-name mapping file: lines 'HumanBodyBone = JointName'");
  zmp_cmd->add_option("--unit", zmp.unit,
                      "Length unit of the file: m, cm, mm, inch, cmu or metres per unit (default: guessed)");
  zmp_cmd->add_option("--mass", zmp.body_mass_kg, "Body mass, kg")->check(CLI::Range(5.0, 500.0));
  zmp_cmd->add_option("--sex", zmp.sex, "de Leva table: male or female");
  zmp_cmd->add_option("--trunk", zmp.trunk,
                      "Where the trunk's mass lies: spine (along the spine joints, default) or straight (one rigid "
                      "trunk from the hips to the neck)");
  zmp_cmd->add_flag("--both-trunks", zmp.both_trunks,
                    "Judge under the estimator family with the trunk along the spine and straight (16 members); the "
                    "robust filter then corrects under both");
  zmp_cmd->add_option("--foot-length", zmp.foot_length_m, "Sole length, m (default: from the skeleton)")
      ->check(CLI::Range(0.05, 0.5));
  zmp_cmd->add_option("--ground-height", zmp.ground_height_m,
                      "Ground height in the internal frame, m (default: estimated)");
  zmp_cmd
      ->add_option("--contact-height", zmp.contact_height_m,
                   "A foot point is down below its resting height plus this, m")
      ->check(CLI::Range(0.001, 0.5));
  zmp_cmd->add_option("--contact-speed", zmp.contact_speed_mps, "... and slower than this, m/s")
      ->check(CLI::Range(0.01, 5.0));
  zmp_cmd->add_option("--derivative", zmp.derivative, "kalman_spline (default), kalman, spline or finite_difference");
  zmp_cmd->add_option("--cutoff", zmp.cutoff_hz, "The analysis's smoothing cutoff, Hz")->check(CLI::Range(0.5, 100.0));
  zmp_cmd->add_flag("--full-zmp", zmp.full_zmp, "Include the segments' angular momentum (default: particle form)");
  zmp_cmd
      ->add_option("--correction", zmp.correction,
                   "Correction: waist (default: lean, yaw and pelvis shift, robust under the estimator family) or "
                   "rotation (the first design: the waist rotation, under one estimator)")
      ->check(CLI::IsMember({"rotation", "waist"}));
  zmp_cmd->add_flag("--online", zmp.online,
                    "Correct as a stream: each frame from the ones before it and --lookahead ahead (pelvis shift by "
                    "ZMP preview control)");
  zmp_cmd->add_option("--lookahead", zmp.lookahead_s, "--online: how far ahead the filter sees, s")
      ->check(CLI::Range(0.001, 0.25));
  zmp_cmd
      ->add_option("--plan-weight", zmp.plan_weight,
                   "--online: the planner's weight of a violation of the support polygons ahead against the "
                   "ZMP tracking (0: Kajita's plain preview, one reference move per frame)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  zmp_cmd
      ->add_option("--window-cutoff", zmp.window_cutoff_hz,
                   "--online: the cutoff of the smoothing in the filter's window, Hz (the family that judges the "
                   "result is unchanged)")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 100.0));
  zmp_cmd
      ->add_option(
          "--margin", zmp.margin_m,
          "Aim this far inside the support polygon, m (default: the correction's own; 1 cm, the robust filter 2 cm, "
          "--online 1.5 cm)")
      ->check(CLI::Range(0.0, 0.05));
  zmp_cmd
      ->add_option("--max-correction", zmp.max_correction_rad,
                   "--correction rotation: largest waist rotation per frame, rad")
      ->check(CLI::Range(0.01, 2.0));
  zmp_cmd
      ->add_option("--max-arm-swing", zmp.max_arm_swing_rad,
                   "The robust filter's largest swing of each arm about its shoulder, rad (0: the arms stay as "
                   "captured)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.5));
  zmp_cmd
      ->add_option("--arm-weight", zmp.arm_weight,
                   "The robust filter's cost of a radian of arm swing, as metres of ZMP outside (lower: the arms "
                   "swing more, on more frames)")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 10.0));
  zmp_cmd->add_option("--iterations", zmp.max_iterations, "Solver iterations at most")->check(CLI::Range(0, 10000));
  zmp_cmd->add_flag("--keep-tpose", zmp.keep_tpose, "Analyse a leading T-pose frame too");
  zmp_cmd->add_flag("-q,--quiet", zmp.quiet, "No report on stdout");

  tonus::tools::ExperimentOptions experiment;
  CLI::App* experiment_cmd = app.add_subcommand(
      "experiment", "Run one of the avatar controller's experiments and write its JSON report and SVG plot");
  experiment_cmd->add_option("name", experiment.name, "cube-on-hand, brace or track")
      ->required()
      ->check(CLI::IsMember({"cube-on-hand", "brace", "track"}));
  experiment_cmd->add_option("--json", experiment.json, "Write the JSON report here");
  experiment_cmd->add_option("--svg", experiment.svg, "Write the plot here");
  experiment_cmd->add_option("--stiffness", experiment.stiffness, "cube-on-hand: the performer's stiffness, 0..1")
      ->check(CLI::Range(0.0, 1.0));
  experiment_cmd->add_option("--clip", experiment.clips, "track: BVH clips to follow (default: the bundled CMU walk)");
  experiment_cmd->add_option("--seconds", experiment.seconds, "track: at most this much of each clip")
      ->check(CLI::Range(0.1, 600.0));
  experiment_cmd->add_flag("-q,--quiet", experiment.quiet, "No report on stdout");

  tonus::tools::IkCommandOptions ik;
  CLI::App* ik_cmd = app.add_subcommand(
      "ik",
      "Solve a real clip's full body from the trackers a performer would wear (3: head, hands; 6: + waist, "
      "feet) and compare with the clip");
  ik_cmd->add_option("clip", ik.clip, "Input BVH file")->required();
  ik_cmd->add_option("--trackers", ik.trackers, "3 or 6")->check(CLI::IsMember({3, 6}));
  ik_cmd->add_option("--json", ik.json, "Write the JSON report here");
  ik_cmd->add_option("--svg", ik.svg, "Write the plot here");
  ik_cmd->add_option("--mapping", ik.mapping, "Joint-name mapping file: lines 'HumanBodyBone = JointName'");
  ik_cmd->add_option("--seconds", ik.seconds, "At most this much of the clip")->check(CLI::Range(0.1, 3600.0));
  ik_cmd->add_flag("-q,--quiet", ik.quiet, "No report on stdout");

  tonus::tools::CtlOptions ctl;
  CLI::App* ctl_cmd = tonus::tools::add_ctl_command(app, ctl);
  CLI11_PARSE(app, argc, argv);
  if (ctl_cmd->parsed()) return tonus::tools::run_ctl_command(ctl);
  if (ik_cmd->parsed()) return tonus::tools::run_ik_command(ik);
  if (experiment_cmd->parsed()) return tonus::tools::run_experiment(experiment);
  if (zmp_cmd->parsed()) return tonus::tools::run_zmp_command(zmp);
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
