#include "tonus/host/control/requests.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstddef>
#include <string>
#include <utility>

#include "describe.hpp"

namespace tonus::control {

namespace {

using nlohmann::json;

Invalid invalid(std::string field, const std::string& what) {
  std::string message = field + ": " + what;
  return Invalid{std::move(field), std::move(message)};
}

// The body as a JSON object, or why not.
std::variant<json, Invalid> parse_object(std::string_view body) {
  if (body.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    return invalid("body", "empty; expected a JSON object");
  }
  json doc;
  try {
    doc = json::parse(body);
  } catch (const json::exception& e) {
    return invalid("body", "not valid JSON (" + strip_json_exception(e.what()) + ")");
  }
  if (!doc.is_object()) return invalid("body", "expected a JSON object, got " + describe(doc));
  return doc;
}

// An optional number field: absent or null -> nullopt; else a finite number in range.
std::variant<std::optional<double>, Invalid> number_field(const json& doc, const char* field, Range range,
                                                          const char* unit) {
  const auto it = doc.find(field);
  if (it == doc.end() || it->is_null()) return std::optional<double>{};
  if (!it->is_number()) return invalid(field, "expected a number, got " + describe(*it));
  const double v = it->get<double>();
  if (!std::isfinite(v)) return invalid(field, describe(*it) + " is not a finite number");
  if (!range.contains(v)) {
    return invalid(field, fmt::format("{} is out of range {}..{} {}", describe(*it), range.min, range.max, unit));
  }
  return std::optional<double>{v};
}

std::string bone_names() {
  std::string names;
  for (const sim::BoneInfo& b : sim::kBones) {
    if (!names.empty()) names += ", ";
    names += b.name;
  }
  return names;
}

}  // namespace

std::variant<GiftRequest, Invalid> parse_gift_request(std::string_view body) {
  auto parsed = parse_object(body);
  if (auto* bad = std::get_if<Invalid>(&parsed)) return std::move(*bad);
  const json& doc = std::get<json>(parsed);

  static constexpr std::array<std::string_view, 7> kFields{"kind",      "bone",     "mass_kg",   "size_m",
                                                           "speed_mps", "height_m", "lifetime_s"};
  for (const auto& [key, value] : doc.items()) {
    bool known = false;
    for (std::string_view f : kFields) known = known || key == f;
    if (!known) {
      return invalid(clip(key, 40),
                     "unknown field (expected kind, bone, mass_kg, size_m, speed_mps, height_m, lifetime_s)");
    }
  }

  GiftRequest r;
  const auto kind = doc.find("kind");
  if (kind == doc.end() || kind->is_null()) return invalid("kind", "required (\"ball\" or \"cube\")");
  if (!kind->is_string()) return invalid("kind", "expected a string, got " + describe(*kind));
  const auto k = gift_kind_from_name(kind->get_ref<const std::string&>());
  if (!k) return invalid("kind", "unknown kind " + describe(*kind) + " (expected \"ball\" or \"cube\")");
  r.kind = *k;

  const auto bone = doc.find("bone");
  if (bone != doc.end() && !bone->is_null()) {
    if (!bone->is_string()) return invalid("bone", "expected a string, got " + describe(*bone));
    const std::string& name = bone->get_ref<const std::string&>();
    if (!name.empty()) {
      r.bone = sim::bone_from_name(name);
      if (!r.bone) {
        return invalid("bone", "unknown bone " + describe(*bone) + " (expected one of " + bone_names() + ")");
      }
    }
  }

  struct NumberField {
    const char* name;
    Range range;
    const char* unit;
    std::optional<double>* out;
  };
  const std::array<NumberField, 5> numbers{{
      {"mass_kg", kMassKgRange, "kg", &r.mass_kg},
      {"size_m", kSizeMRange, "m", &r.size_m},
      {"speed_mps", kSpeedMpsRange, "m/s", &r.speed_mps},
      {"height_m", kHeightMRange, "m", &r.height_m},
      {"lifetime_s", kLifetimeSRange, "s", &r.lifetime_s},
  }};
  for (const NumberField& f : numbers) {
    auto v = number_field(doc, f.name, f.range, f.unit);
    if (auto* bad = std::get_if<Invalid>(&v)) return std::move(*bad);
    *f.out = std::get<std::optional<double>>(v);
  }
  if (r.kind == GiftKind::cube && r.speed_mps)
    return invalid("speed_mps", "applies to a ball only (a cube is dropped)");
  if (r.kind == GiftKind::ball && r.height_m) return invalid("height_m", "applies to a cube only (a ball is thrown)");
  return r;
}

std::variant<std::optional<Levels>, Invalid> parse_stiffness_request(std::string_view body) {
  auto parsed = parse_object(body);
  if (auto* bad = std::get_if<Invalid>(&parsed)) return std::move(*bad);
  const json& doc = std::get<json>(parsed);
  for (const auto& [key, value] : doc.items()) {
    if (key != "levels") return invalid(clip(key, 40), "unknown field (expected levels)");
  }
  const auto it = doc.find("levels");
  if (it == doc.end()) {
    return invalid("levels", "required: [right_arm, left_arm, trunk, legs] each 0..1, or null to release");
  }
  if (it->is_null()) return std::optional<Levels>{};
  if (!it->is_array()) return invalid("levels", "expected an array of 4 numbers or null, got " + describe(*it));
  if (it->size() != kLevelCount) return invalid("levels", fmt::format("expected 4 numbers, got {}", it->size()));
  Levels levels{};
  for (std::size_t i = 0; i < kLevelCount; ++i) {
    const json& v = (*it)[i];
    const std::string field = fmt::format("levels[{}]", i);
    if (!v.is_number()) return invalid(field, "expected a number, got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x) || x < 0.0 || x > 1.0) return invalid(field, describe(v) + " is out of range 0..1");
    levels[i] = x;
  }
  return std::optional<Levels>{levels};
}

json to_json(const GiftRequest& request) {
  json body = json::object();
  body["kind"] = std::string(to_string(request.kind));
  if (request.bone) body["bone"] = std::string(sim::name(*request.bone));
  const std::array<std::pair<const char*, const std::optional<double>*>, 5> numbers{{
      {"mass_kg", &request.mass_kg},
      {"size_m", &request.size_m},
      {"speed_mps", &request.speed_mps},
      {"height_m", &request.height_m},
      {"lifetime_s", &request.lifetime_s},
  }};
  for (const auto& [name, value] : numbers) {
    if (*value) body[name] = **value;
  }
  return body;
}

json stiffness_body(const std::optional<Levels>& levels) {
  json body = json::object();
  body["levels"] = levels ? json(*levels) : json(nullptr);
  return body;
}

}  // namespace tonus::control
