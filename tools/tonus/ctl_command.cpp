#include "ctl_command.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "tonus/host/control/client.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::tools {

namespace {

// A whole argument as a number ("0.5"), else nullopt.
std::optional<double> to_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

CLI::App* add_ctl_command(CLI::App& app, CtlOptions& opt) {
  CLI::App* ctl = app.add_subcommand(
      "ctl", "Control a running tonusd (its HTTP API): status, gifts, a stiffness override, calibration");
  ctl->fallthrough();  // --host / --port also after the action
  ctl->require_subcommand(1);
  ctl->add_option("--host", opt.host, "The daemon's control address")->capture_default_str();
  ctl->add_option("--port", opt.port, "The daemon's control port")->capture_default_str()->check(CLI::Range(1, 65535));
  ctl->add_option("--timeout", opt.timeout_s, "Give up after this many seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.05, 600.0));

  using Action = CtlOptions::Action;

  ctl->add_subcommand("status", "Print the daemon's status")->callback([&opt] { opt.action = Action::status; });

  CLI::App* gift = ctl->add_subcommand("gift", "Throw a ball at the avatar or drop a cube on it");
  gift->add_option_function<std::string>(
          "kind", [&opt](const std::string& k) { opt.gift.kind = *control::gift_kind_from_name(k); }, "ball or cube")
      ->required()
      ->check(CLI::IsMember({"ball", "cube"}));
  std::vector<std::string> bones;
  bones.reserve(sim::kBones.size());
  for (const sim::BoneInfo& b : sim::kBones) bones.emplace_back(b.name);
  gift->add_option_function<std::string>(
          "--bone", [&opt](const std::string& b) { opt.gift.bone = sim::bone_from_name(b); },
          "Target bone, a HumanBodyBones name (default: the kind's own, e.g. Chest, RightHand)")
      ->check(CLI::IsMember(bones));
  gift->add_option_function<double>(
      "--mass-kg", [&opt](const double& v) { opt.gift.mass_kg = v; }, "Mass, kg (0.01..20)");
  gift->add_option_function<double>(
      "--size-m", [&opt](const double& v) { opt.gift.size_m = v; }, "Ball diameter or cube edge, m (0.01..1)");
  gift->add_option_function<double>(
      "--speed-mps", [&opt](const double& v) { opt.gift.speed_mps = v; }, "Ball: launch speed, m/s (0..40)");
  gift->add_option_function<double>(
      "--height-m", [&opt](const double& v) { opt.gift.height_m = v; }, "Cube: drop height above the bone, m (0..3)");
  gift->add_option_function<double>(
      "--lifetime-s", [&opt](const double& v) { opt.gift.lifetime_s = v; }, "Removed after this, s (0..600; 0: never)");
  gift->callback([&opt] { opt.action = Action::gift; });

  ctl->add_subcommand("clear", "Remove every gift")->callback([&opt] { opt.action = Action::clear; });

  CLI::App* stiffness = ctl->add_subcommand(
      "stiffness", "Override the band: four levels 0..1 (right arm, left arm, trunk, legs), or 'release'");
  auto levels_text = std::make_shared<std::vector<std::string>>();
  stiffness->add_option("levels", *levels_text, "A B C D, or release")->required()->expected(1, 4);
  stiffness->callback([&opt, levels_text] {
    const std::vector<std::string>& args = *levels_text;
    opt.action = Action::stiffness;
    if (args.size() == 1 && args[0] == "release") {
      opt.levels.reset();
      return;
    }
    if (args.size() != control::kLevelCount) {
      throw CLI::ValidationError("levels", "expected four levels (right arm, left arm, trunk, legs) or 'release'");
    }
    control::Levels levels{};
    for (std::size_t i = 0; i < levels.size(); ++i) {
      const auto v = to_number(args[i]);
      if (!v) throw CLI::ValidationError("levels", fmt::format("'{}' is not a number", args[i]));
      levels[i] = *v;
    }
    opt.levels = levels;
  });

  CLI::App* calibrate = ctl->add_subcommand("calibrate", "Run a calibration phase (rest, mvc) or abort it");
  calibrate
      ->add_option_function<std::string>(
          "phase", [&opt](const std::string& c) { opt.calibration = *control::calibration_command_from_name(c); },
          "rest, mvc or abort")
      ->required()
      ->check(CLI::IsMember({"rest", "mvc", "abort"}));
  calibrate->callback([&opt] { opt.action = Action::calibrate; });
  return ctl;
}

int run_ctl_command(const CtlOptions& opt) {
  using Action = CtlOptions::Action;
  const control::ControlClient client(opt.host, opt.port, opt.timeout_s);
  control::ClientReply r;
  switch (opt.action) {
    case Action::status: r = client.status(); break;
    case Action::gift: r = client.gift(opt.gift); break;
    case Action::clear: r = client.clear_gifts(); break;
    case Action::stiffness: r = client.set_stiffness(opt.levels); break;
    case Action::calibrate: r = client.calibrate(opt.calibration); break;
    case Action::none:
      fmt::print(stderr, "tonus ctl: no action (status, gift, clear, stiffness, calibrate)\n");
      return 1;
  }
  if (!r.reached()) {
    fmt::print(stderr, "tonus ctl: {} (is tonusd running? --host / --port)\n", r.error);
    return 2;
  }
  if (!r.body.is_null()) fmt::print("{}\n", r.body.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
  if (r.ok()) return 0;
  std::string why = r.error;
  if (why.empty() && r.body.is_object() && r.body.contains("error") && r.body["error"].is_string()) {
    why = r.body["error"].get<std::string>();
  }
  fmt::print(stderr, "tonus ctl: HTTP {}{}{}\n", r.status, why.empty() ? "" : ": ", why);
  return 1;
}

}  // namespace tonus::tools
