#include "tonus/host/control/api.hpp"

#include "describe.hpp"

namespace tonus::control {

std::string_view to_string(GiftKind k) {
  switch (k) {
    case GiftKind::ball: return "ball";
    case GiftKind::cube: return "cube";
  }
  return "?";
}

std::optional<GiftKind> gift_kind_from_name(std::string_view name) {
  if (name == "ball") return GiftKind::ball;
  if (name == "cube") return GiftKind::cube;
  return std::nullopt;
}

std::string_view to_string(CalibrationCommand c) {
  switch (c) {
    case CalibrationCommand::rest: return "rest";
    case CalibrationCommand::mvc: return "mvc";
    case CalibrationCommand::abort: return "abort";
  }
  return "?";
}

std::optional<CalibrationCommand> calibration_command_from_name(std::string_view name) {
  if (name == "rest") return CalibrationCommand::rest;
  if (name == "mvc") return CalibrationCommand::mvc;
  if (name == "abort") return CalibrationCommand::abort;
  return std::nullopt;
}

Reply Reply::error(int status, std::string_view message) {
  Reply r{status, nlohmann::json::object()};
  r.body["error"] = std::string(message);
  return r;
}

std::string clip(std::string_view s, std::size_t n) {
  if (s.size() <= n) return std::string(s);
  return std::string(s.substr(0, n)) + "...";
}

std::string describe(const nlohmann::json& v) {
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return clip(dump_safe(v), 60);
}

std::string strip_json_exception(std::string_view what) {
  if (!what.empty() && what.front() == '[') {
    const auto end = what.find("] ");
    if (end != std::string_view::npos) what.remove_prefix(end + 2);
  }
  return clip(what, 200);
}

std::string dump_safe(const nlohmann::json& v, int indent) {
  return v.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace tonus::control
