#include "tonus/host/viewer/json.hpp"

#include <cmath>
#include <cstddef>
#include <exception>
#include <string>
#include <utility>

namespace tonus::viewer {

namespace {

using nlohmann::json;

// Rounding steps (docs/viewer.md, "Numbers").
constexpr double kMetres = 1e5;     // 1e-5 m
constexpr double kQuat = 1e6;       // 1e-6
constexpr double kNewtons = 1e3;    // 1e-3 N
constexpr double kSeconds = 1e6;    // 1e-6 s
constexpr double kMilli = 1e3;      // 1e-3 ms or us
constexpr double kStiffness = 1e4;  // 1e-4
constexpr double kUnrounded = 0.0;  // as is

// A finite number rounded to 1/scale (none when scale is 0), or null. Huge
// values are left as they are (scaling them would overflow); -0 prints as 0.
json number(double v, double scale) {
  if (!std::isfinite(v)) return nullptr;
  if (scale > 0.0 && std::abs(v) < 1e15 / scale) v = std::round(v * scale) / scale;
  return v + 0.0;
}

template <std::size_t N>
json numbers(const std::array<double, N>& v, double scale) {
  json out = json::array();
  for (double x : v) out.push_back(number(x, scale));
  return out;
}

// A bone pose as [px, py, pz, qx, qy, qz, qw].
json pose(const BonePose& p) {
  json out = json::array();
  for (double x : p.pos) out.push_back(number(x, kMetres));
  for (double x : p.quat) out.push_back(number(x, kQuat));
  return out;
}

json poses(const std::vector<BonePose>& ps) {
  json out = json::array();
  for (const BonePose& p : ps) out.push_back(pose(p));
  return out;
}

std::string dump(const json& doc) { return doc.dump(-1, ' ', false, json::error_handler_t::replace); }

// ---- parsing -----------------------------------------------------------------

// The deepest nesting of arrays and objects in `text` (strings skipped), so
// a hostile message cannot make the parser or dump() recurse deeply.
int nesting_depth(std::string_view text) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      ++depth;
      if (depth > deepest) deepest = depth;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// A short description of a JSON value for error messages.
std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case json::value_t::string: {
      std::string s = v.get<std::string>();
      if (s.size() > 40) s = s.substr(0, 40) + "...";
      return "a string \"" + s + "\"";
    }
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "the number " + dump(v);
    case json::value_t::binary:
    case json::value_t::discarded: break;
  }
  return "a value of another kind";
}

// The message's "id" when it is a usable request id.
std::optional<std::uint64_t> usable_id(const json& doc) {
  const auto it = doc.find("id");
  if (it == doc.end() || !it->is_number_unsigned()) return std::nullopt;
  const auto id = it->get<std::uint64_t>();
  if (id > kMaxRequestId) return std::nullopt;
  return id;
}

BadMessage bad(std::string error, std::optional<std::uint64_t> id = std::nullopt) {
  return BadMessage{std::move(error), id};
}

// Refuses members other than `allowed` (a typo is an error, not ignored).
std::optional<std::string> unknown_member(const json& doc, std::initializer_list<std::string_view> allowed) {
  for (const auto& item : doc.items()) {
    bool known = false;
    for (std::string_view a : allowed) known = known || item.key() == a;
    if (!known) {
      std::string key = item.key();
      if (key.size() > 40) key = key.substr(0, 40) + "...";
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      std::string message = "unknown field \"";
      message += key;
      message += "\" (expected ";
      message += list;
      message += ")";
      return message;
    }
  }
  return std::nullopt;
}

ClientMessage parse_request(const json& doc) {
  const auto id = usable_id(doc);
  const auto id_it = doc.find("id");
  if (id_it == doc.end()) return bad("request: \"id\" is required (an integer 0..2^53-1)");
  if (!id) return bad("request: \"id\" must be an integer 0..2^53-1, got " + describe(*id_it));
  if (auto unknown = unknown_member(doc, {"type", "id", "method", "path", "body"})) {
    return bad("request: " + *unknown, id);
  }

  RequestMessage r;
  r.id = *id;
  const auto method = doc.find("method");
  if (method == doc.end()) return bad("request: \"method\" is required (\"GET\", \"POST\", \"PUT\", \"DELETE\")", id);
  if (!method->is_string()) return bad("request: \"method\" must be a string, got " + describe(*method), id);
  r.method = method->get<std::string>();
  bool token = !r.method.empty() && r.method.size() <= 16;
  for (char c : r.method) token = token && c >= 'A' && c <= 'Z';
  if (!token) return bad("request: \"method\" must be an upper-case HTTP method, got " + describe(*method), id);

  const auto path = doc.find("path");
  if (path == doc.end()) return bad("request: \"path\" is required (e.g. \"/gifts\")", id);
  if (!path->is_string()) return bad("request: \"path\" must be a string, got " + describe(*path), id);
  r.path = path->get<std::string>();
  if (r.path.empty() || r.path.front() != '/') return bad("request: \"path\" must start with '/'", id);
  if (r.path.size() > kMaxRequestPathBytes) {
    return bad("request: \"path\" is longer than " + std::to_string(kMaxRequestPathBytes) + " bytes", id);
  }
  for (char c : r.path) {
    if (static_cast<unsigned char>(c) < 0x20U || c == 0x7f)
      return bad("request: \"path\" holds a control character", id);
  }

  const auto body = doc.find("body");
  if (body != doc.end() && !body->is_null()) r.body = dump(*body);
  return r;
}

ClientMessage parse_playback(const json& doc) {
  if (auto unknown = unknown_member(doc, {"type", "action", "position_s"})) return bad("playback: " + *unknown);
  const auto action = doc.find("action");
  if (action == doc.end()) return bad("playback: \"action\" is required (\"play\", \"pause\" or \"seek\")");
  if (!action->is_string()) return bad("playback: \"action\" must be a string, got " + describe(*action));
  const auto& name = action->get_ref<const std::string&>();
  PlaybackMessage m;
  if (name == "play") {
    m.action = PlaybackAction::play;
  } else if (name == "pause") {
    m.action = PlaybackAction::pause;
  } else if (name == "seek") {
    m.action = PlaybackAction::seek;
  } else {
    return bad("playback: unknown action " + describe(*action) + " (expected \"play\", \"pause\" or \"seek\")");
  }
  const auto position = doc.find("position_s");
  if (m.action == PlaybackAction::seek) {
    if (position == doc.end()) return bad("playback: seek needs \"position_s\" (seconds, >= 0)");
    if (!position->is_number()) return bad("playback: \"position_s\" must be a number, got " + describe(*position));
    m.position_s = position->get<double>();
    if (!std::isfinite(m.position_s) || m.position_s < 0.0) {
      return bad("playback: \"position_s\" must be finite and >= 0, got " + describe(*position));
    }
  } else if (position != doc.end()) {
    return bad("playback: \"position_s\" applies to seek only");
  }
  return m;
}

}  // namespace

std::string to_json(const Scene& scene) {
  json bones = json::array();
  for (const BoneInfo& b : scene.bones) {
    bones.push_back({{"name", b.name}, {"parent", b.parent}, {"group", b.group}, {"rest", pose(b.rest)}});
  }
  json geoms = json::array();
  for (const GeomInfo& g : scene.geoms) {
    geoms.push_back({{"bone", g.bone},
                     {"shape", g.shape},
                     {"radius_m", number(g.radius_m, kMetres)},
                     {"half_length_m", number(g.half_length_m, kMetres)},
                     {"half_extents_m", numbers(g.half_extents_m, kMetres)},
                     {"pos", numbers(g.pos, kMetres)},
                     {"quat", numbers(g.quat, kQuat)}});
  }
  const json doc = {
      {"type", "scene"},
      {"protocol", kProtocolVersion},
      {"mode", scene.mode},
      {"bones", std::move(bones)},
      {"geoms", std::move(geoms)},
      {"groups", scene.groups},
      {"gift_bones", scene.gift_bones},
      {"ground_z_m", number(scene.ground_z_m, kMetres)},
      {"rate_hz", number(scene.rate_hz, kUnrounded)},
      {"vrm", scene.vrm ? json{{"url", scene.vrm->url}, {"name", scene.vrm->name}, {"bytes", scene.vrm->bytes}}
                        : json(nullptr)}};
  return dump(doc);
}

std::string to_json(const Frame& frame) {
  json objects = json::array();
  for (const ObjectFrame& o : frame.objects) {
    objects.push_back({{"id", o.id},
                       {"kind", o.kind},
                       {"size_m", number(o.size_m, kMetres)},
                       {"pos", numbers(o.pos, kMetres)},
                       {"quat", numbers(o.quat, kQuat)}});
  }
  json contacts = json::array();
  for (const ContactFrame& c : frame.contacts) {
    contacts.push_back({{"pos", numbers(c.pos, kMetres)}, {"force_n", numbers(c.force_n, kNewtons)}});
  }
  json support = json::array();
  for (const Vec2& p : frame.support) support.push_back(numbers(p, kMetres));
  json stiffness = json::array();
  for (double s : frame.stiffness) stiffness.push_back(number(s, kStiffness));

  const BandFrame& b = frame.band;
  const MetricsFrame& m = frame.metrics;
  json playback = nullptr;
  if (frame.playback) {
    playback = {{"duration_s", number(frame.playback->duration_s, kSeconds)},
                {"position_s", number(frame.playback->position_s, kSeconds)},
                {"playing", frame.playback->playing}};
  }
  const json doc = {{"type", "frame"},
                    {"tick", frame.tick},
                    {"time_s", number(frame.time_s, kSeconds)},
                    {"avatar", poses(frame.avatar)},
                    {"reference", poses(frame.reference)},
                    {"objects", std::move(objects)},
                    {"contacts", std::move(contacts)},
                    {"zmp", frame.zmp ? numbers(*frame.zmp, kMetres) : json(nullptr)},
                    {"support", std::move(support)},
                    {"stiffness", std::move(stiffness)},
                    {"override_active", frame.override_active},
                    {"tracker_state", frame.tracker_state},
                    {"band",
                     {{"source", b.source},
                      {"connected", b.connected},
                      {"live", b.live},
                      {"calibrated", b.calibrated},
                      {"latency_p50_ms", number(b.latency_p50_ms, kMilli)},
                      {"latency_p99_ms", number(b.latency_p99_ms, kMilli)},
                      {"reports", b.reports},
                      {"lost", b.lost}}},
                    {"metrics",
                     {{"ticks", m.ticks},
                      {"tick_p50_us", number(m.tick_p50_us, kMilli)},
                      {"tick_p99_us", number(m.tick_p99_us, kMilli)},
                      {"tick_max_us", number(m.tick_max_us, kMilli)},
                      {"overruns", m.overruns},
                      {"tracker_rate_hz", number(m.tracker_rate_hz, kMilli)}}},
                    {"playback", std::move(playback)}};
  return dump(doc);
}

std::string reply_json(std::uint64_t id, int status, const nlohmann::json& body) {
  return dump(json{{"type", "reply"}, {"id", id}, {"status", status}, {"body", body}});
}

std::string error_json(std::string_view error, std::optional<std::uint64_t> id) {
  json doc = {{"type", "error"}, {"error", std::string(error)}};
  if (id) doc["id"] = *id;
  return dump(doc);
}

std::string_view to_string(PlaybackAction action) {
  switch (action) {
    case PlaybackAction::play: return "play";
    case PlaybackAction::pause: return "pause";
    case PlaybackAction::seek: return "seek";
  }
  return "?";
}

ClientMessage parse_client_message(std::string_view text) {
  if (text.size() > kMaxClientMessageBytes) {
    return bad("message larger than " + std::to_string(kMaxClientMessageBytes) + " bytes");
  }
  if (nesting_depth(text) > kMaxClientJsonDepth) {
    return bad("message nested deeper than " + std::to_string(kMaxClientJsonDepth) + " levels");
  }
  json doc;
  try {
    doc = json::parse(text);
  } catch (const std::exception& e) {
    std::string what = e.what();
    // nlohmann's messages start with "[json.exception.parse_error.101] ".
    if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
    return bad("not valid JSON (" + what + ")");
  }
  if (!doc.is_object()) return bad("expected a JSON object, got " + describe(doc));
  const auto type = doc.find("type");
  if (type == doc.end()) return bad("\"type\" is required (\"request\" or \"playback\")", usable_id(doc));
  if (!type->is_string()) return bad("\"type\" must be a string, got " + describe(*type), usable_id(doc));
  const auto& name = type->get_ref<const std::string&>();
  if (name == "request") return parse_request(doc);
  if (name == "playback") return parse_playback(doc);
  return bad("unknown type " + describe(*type) + " (expected \"request\" or \"playback\")", usable_id(doc));
}

}  // namespace tonus::viewer
