// The viewer's JSON: the scene and frame messages (field names, rounding,
// non-finite numbers) and the parsing of what a page sends.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>

#include "tonus/host/viewer/json.hpp"
#include "viewer_fixtures.hpp"

namespace tv = tonus::viewer;
using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

template <typename T>
T as(const tv::ClientMessage& m) {
  const T* p = std::get_if<T>(&m);
  REQUIRE_MESSAGE(p != nullptr, "parsed as another kind of message");
  return *p;
}

std::string error_of(std::string_view text) {
  const tv::ClientMessage m = tv::parse_client_message(text);
  const auto* bad = std::get_if<tv::BadMessage>(&m);
  return bad ? bad->error : std::string("(accepted)");
}

}  // namespace

TEST_CASE("viewer json: a scene message has every field, in the scene's order") {
  const json s = json::parse(tv::to_json(tv::testing::small_scene()));
  CHECK(s["type"] == "scene");
  CHECK(s["protocol"] == tv::kProtocolVersion);
  CHECK(s["mode"] == "live");
  REQUIRE(s["bones"].size() == 3);
  CHECK(
      s["bones"][0] ==
      json{{"name", "Hips"}, {"parent", -1}, {"group", 1}, {"rest", json::array({0.0, 0.0, 0.9, 0.0, 0.0, 0.0, 1.0})}});
  CHECK(s["bones"][2] == json{{"name", "RightHand"},
                              {"parent", 1},
                              {"group", 0},
                              {"rest", json::array({0.0, -0.7, 1.4, 0.0, 0.0, 0.707107, 0.707107})}});
  REQUIRE(s["geoms"].size() == 3);
  const json& capsule = s["geoms"][0];
  CHECK(capsule["bone"] == 0);
  CHECK(capsule["shape"] == "capsule");
  CHECK(capsule["radius_m"] == 0.1);
  CHECK(capsule["half_length_m"] == 0.05);
  CHECK(capsule["half_extents_m"] == json::array({0.0, 0.0, 0.0}));
  CHECK(capsule["pos"] == json::array({0.0, 0.0, 0.05}));
  CHECK(capsule["quat"] == json::array({0.0, 0.0, 0.0, 1.0}));
  CHECK(s["geoms"][1]["shape"] == "sphere");
  CHECK(s["geoms"][2]["shape"] == "box");
  CHECK(s["geoms"][2]["half_extents_m"] == json::array({0.04, 0.02, 0.08}));
  CHECK(s["geoms"][2]["quat"] == json::array({0.0, 0.0, 0.707107, 0.707107}));  // rounded to 1e-6
  CHECK(s["groups"] == json::array({"right_arm", "trunk"}));
  CHECK(s["gift_bones"] == json::array({"Chest", "RightHand"}));
  CHECK(s["ground_z_m"] == 0.0);
  CHECK(s["rate_hz"] == 1000.0);
  CHECK(s["vrm"].is_null());  // no avatar
  CHECK(s.size() == 10);      // nothing else

  tv::Scene with = tv::testing::small_scene();
  with.vrm = tv::SceneVrm{"/avatar.vrm", "alice.vrm", 12345};
  CHECK(json::parse(tv::to_json(with))["vrm"] == json{{"url", "/avatar.vrm"}, {"name", "alice.vrm"}, {"bytes", 12345}});
}

TEST_CASE("viewer json: a frame message has every field, poses as [px, py, pz, qx, qy, qz, qw]") {
  tv::Frame f = tv::testing::small_frame(1234);
  f.objects.push_back({7, "ball", 0.11, {1.0, 2.0, 3.0}, {0.0, 0.0, 0.0, 1.0}});
  f.contacts.push_back({{0.1, 0.2, 0.0}, {0.0, 0.0, 350.0}});
  f.override_active = true;
  f.band.calibrated = true;
  f.band.latency_p50_ms = 2.5;
  f.band.latency_p99_ms = 4.25;
  f.band.reports = 500;
  f.band.lost = 3;
  f.metrics.tick_p50_us = 80.0;
  f.metrics.tick_p99_us = 210.0;
  f.metrics.tick_max_us = 900.0;
  f.metrics.overruns = 2;
  f.metrics.tracker_rate_hz = 120.0;
  f.playback = tv::PlaybackFrame{12.0, 3.5, true};

  const json m = json::parse(tv::to_json(f));
  CHECK(m["type"] == "frame");
  CHECK(m["tick"] == 1234);
  CHECK(m["time_s"] == 1.234);
  REQUIRE(m["avatar"].size() == 3);
  CHECK(m["avatar"][1].size() == 7);
  CHECK(m["avatar"][1][2] == 1.3);
  CHECK(m["avatar"][1][6] == 1.0);
  CHECK(m["reference"].size() == 3);
  CHECK(m["objects"][0] ==
        json{{"id", 7}, {"kind", "ball"}, {"size_m", 0.11}, {"pos", {1.0, 2.0, 3.0}}, {"quat", {0.0, 0.0, 0.0, 1.0}}});
  CHECK(m["contacts"][0] == json{{"pos", {0.1, 0.2, 0.0}}, {"force_n", {0.0, 0.0, 350.0}}});
  CHECK(m["zmp"] == json::array({0.0, 0.0}));
  CHECK(m["support"].size() == 4);
  CHECK(m["support"][1] == json::array({0.15, -0.15}));
  CHECK(m["stiffness"] == json::array({0.5, 0.25}));
  CHECK(m["override_active"] == true);
  CHECK(m["tracker_state"] == "live");
  CHECK(m["band"] == json{{"source", "sim"},
                          {"connected", true},
                          {"live", true},
                          {"calibrated", true},
                          {"latency_p50_ms", 2.5},
                          {"latency_p99_ms", 4.25},
                          {"reports", 500},
                          {"lost", 3}});
  CHECK(m["metrics"] == json{{"ticks", 1234},
                             {"tick_p50_us", 80.0},
                             {"tick_p99_us", 210.0},
                             {"tick_max_us", 900.0},
                             {"overruns", 2},
                             {"tracker_rate_hz", 120.0}});
  CHECK(m["playback"] == json{{"duration_s", 12.0}, {"position_s", 3.5}, {"playing", true}});
  CHECK(m.size() == 15);

  // Absent optionals are explicit nulls.
  f.zmp.reset();
  f.playback.reset();
  const json n = json::parse(tv::to_json(f));
  CHECK(n["zmp"].is_null());
  CHECK(n["playback"].is_null());
}

TEST_CASE("viewer json: NaN and infinities become null, -0 becomes 0, everything else stays a number") {
  tv::Frame f = tv::testing::small_frame(1);
  f.avatar[0].pos = {kNaN, kInf, -kInf};
  f.avatar[0].quat = {-0.0, 0.0, kNaN, 1.0};
  f.stiffness = {kNaN, 0.5};
  f.zmp = tv::Vec2{kInf, 0.1};
  f.time_s = kNaN;
  f.band.latency_p99_ms = kInf;
  const std::string text = tv::to_json(f);
  CHECK(text.find("NaN") == std::string::npos);
  CHECK(text.find("nan") == std::string::npos);
  CHECK(text.find("inf") == std::string::npos);
  CHECK(text.find("-0.0,") == std::string::npos);
  CHECK(text.find("-0.0]") == std::string::npos);
  const json m = json::parse(text);
  CHECK(m["avatar"][0] == json::array({nullptr, nullptr, nullptr, 0.0, 0.0, nullptr, 1.0}));
  CHECK(m["avatar"][1][0].is_number());
  CHECK(m["stiffness"] == json::array({nullptr, 0.5}));
  CHECK(m["zmp"] == json::array({nullptr, 0.1}));
  CHECK(m["time_s"].is_null());
  CHECK(m["band"]["latency_p99_ms"].is_null());
  CHECK(m["band"]["latency_p50_ms"] == 0.0);
}

TEST_CASE("viewer json: numbers come back within half their rounding step, and print short") {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> metres(-50.0, 50.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> newtons(-5000.0, 5000.0);
  tv::Frame f = tv::testing::small_frame(1);
  for (int i = 0; i < 200; ++i) {
    f.avatar.push_back({{metres(rng), metres(rng), metres(rng)}, {unit(rng), unit(rng), unit(rng), unit(rng)}});
    f.contacts.push_back({{metres(rng), metres(rng), metres(rng)}, {newtons(rng), newtons(rng), newtons(rng)}});
  }
  f.avatar.push_back({{1e300, -1e300, 123456789.123456789}, {0.0, 0.0, 0.0, 1.0}});  // too large to scale: as is
  const std::string text = tv::to_json(f);
  const json m = json::parse(text);
  REQUIRE(m["avatar"].size() == f.avatar.size());
  for (std::size_t i = 0; i < f.avatar.size(); ++i) {
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(std::abs(m["avatar"][i][k].get<double>() - f.avatar[i].pos[k]) <= 0.5e-5 * (1.0 + 1e-9));
    }
    for (std::size_t k = 0; k < 4; ++k) {
      CHECK(std::abs(m["avatar"][i][3 + k].get<double>() - f.avatar[i].quat[k]) <= 0.5e-6 * (1.0 + 1e-9));
    }
  }
  for (std::size_t i = 0; i < f.contacts.size(); ++i) {
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(std::abs(m["contacts"][i]["force_n"][k].get<double>() - f.contacts[i].force_n[k]) <= 0.5e-3 * 1.000001);
    }
  }
  CHECK(m["avatar"].back()[0] == 1e300);
  // Rounded values print without a long tail: at most 5 decimals for metres.
  const json one = json::parse(tv::to_json([] {
    tv::Frame g = tv::testing::small_frame(1);
    g.avatar[0].pos = {0.1234567890123, -1.0 / 3.0, 2.0 / 3.0};
    return g;
  }()));
  CHECK(one["avatar"][0][0].dump() == "0.12346");
  CHECK(one["avatar"][0][1].dump() == "-0.33333");
  CHECK(one["avatar"][0][2].dump() == "0.66667");
  CHECK(text.size() < 60000);
}

TEST_CASE("viewer json: invalid UTF-8 in a string is replaced, never thrown") {
  tv::Frame f = tv::testing::small_frame(1);
  f.tracker_state = std::string("li\xff\xfeve");
  std::string text;
  CHECK_NOTHROW(text = tv::to_json(f));
  const json m = json::parse(text);
  CHECK(m["tracker_state"] == "li\xEF\xBF\xBD\xEF\xBF\xBDve");
  tv::Scene s = tv::testing::small_scene();
  s.bones[0].name = "\xc3";
  CHECK_NOTHROW(text = tv::to_json(s));
  CHECK(json::parse(text)["type"] == "scene");
}

TEST_CASE("viewer json: replies and errors") {
  const json r = json::parse(tv::reply_json(42, 201, {{"id", 7}}));
  CHECK(r == json{{"type", "reply"}, {"id", 42}, {"status", 201}, {"body", {{"id", 7}}}});
  const json e = json::parse(tv::error_json("bad thing", 9));
  CHECK(e == json{{"type", "error"}, {"error", "bad thing"}, {"id", 9}});
  const json e2 = json::parse(tv::error_json("bad thing"));
  CHECK(e2 == json{{"type", "error"}, {"error", "bad thing"}});
}

TEST_CASE("viewer json: a request message is parsed with its body as JSON text") {
  const auto r = as<tv::RequestMessage>(tv::parse_client_message(
      R"({"type":"request","id":5,"method":"POST","path":"/gifts","body":{"kind":"ball","bone":"Chest"}})"));
  CHECK(r.id == 5);
  CHECK(r.method == "POST");
  CHECK(r.path == "/gifts");
  CHECK(json::parse(r.body) == json{{"kind", "ball"}, {"bone", "Chest"}});

  const auto g =
      as<tv::RequestMessage>(tv::parse_client_message(R"({"type":"request","id":0,"method":"GET","path":"/status"})"));
  CHECK(g.body.empty());
  const auto n = as<tv::RequestMessage>(tv::parse_client_message(
      R"({"type":"request","id":9007199254740991,"method":"PUT","path":"/stiffness","body":null})"));
  CHECK(n.id == tv::kMaxRequestId);
  CHECK(n.body.empty());
  const auto levels = as<tv::RequestMessage>(tv::parse_client_message(
      R"({"type":"request","id":1,"method":"PUT","path":"/stiffness","body":{"levels":[0.5,0.5,0.5,0.5]}})"));
  CHECK(json::parse(levels.body)["levels"].size() == 4);
}

TEST_CASE("viewer json: playback messages") {
  CHECK(as<tv::PlaybackMessage>(tv::parse_client_message(R"({"type":"playback","action":"play"})")).action ==
        tv::PlaybackAction::play);
  CHECK(as<tv::PlaybackMessage>(tv::parse_client_message(R"({"type":"playback","action":"pause"})")).action ==
        tv::PlaybackAction::pause);
  const auto seek =
      as<tv::PlaybackMessage>(tv::parse_client_message(R"({"type":"playback","action":"seek","position_s":2.5})"));
  CHECK(seek.action == tv::PlaybackAction::seek);
  CHECK(seek.position_s == 2.5);
  CHECK(tv::to_string(tv::PlaybackAction::seek) == "seek");
}

TEST_CASE("viewer json: malformed client messages are refused with a message naming the fault") {
  CHECK(error_of("").find("not valid JSON") != std::string::npos);
  CHECK(error_of("{\"type\":").find("not valid JSON") != std::string::npos);
  CHECK(error_of("[1,2]") == "expected a JSON object, got an array");
  CHECK(error_of("42") == "expected a JSON object, got the number 42");
  CHECK(error_of("{}").find("\"type\" is required") != std::string::npos);
  CHECK(error_of(R"({"type":3})").find("\"type\" must be a string") != std::string::npos);
  CHECK(error_of(R"({"type":"hello"})").find("unknown type") != std::string::npos);
  CHECK(error_of(R"({"type":"request","method":"GET","path":"/status"})").find("\"id\" is required") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":-1,"method":"GET","path":"/status"})").find("\"id\" must be") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1.5,"method":"GET","path":"/status"})").find("\"id\" must be") !=
        std::string::npos);
  CHECK(
      error_of(R"({"type":"request","id":9007199254740992,"method":"GET","path":"/status"})").find("\"id\" must be") !=
      std::string::npos);
  CHECK(error_of(R"({"type":"request","id":"7","method":"GET","path":"/status"})").find("\"id\" must be") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"path":"/status"})").find("\"method\" is required") != std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"get","path":"/status"})").find("upper-case") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"GET"})").find("\"path\" is required") != std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"GET","path":"status"})").find("must start with '/'") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"GET","path":"/st\natus"})").find("control character") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"GET","path":"/)" + std::string(600, 'a') + "\"}")
            .find("longer than") != std::string::npos);
  CHECK(
      error_of(R"({"type":"request","id":1,"method":"GET","path":"/status","bdy":{}})").find("unknown field \"bdy\"") !=
      std::string::npos);
  CHECK(error_of(R"({"type":"playback"})").find("\"action\" is required") != std::string::npos);
  CHECK(error_of(R"({"type":"playback","action":"rewind"})").find("unknown action") != std::string::npos);
  CHECK(error_of(R"({"type":"playback","action":"seek"})").find("needs \"position_s\"") != std::string::npos);
  CHECK(error_of(R"({"type":"playback","action":"seek","position_s":-1})").find(">= 0") != std::string::npos);
  CHECK(error_of(R"({"type":"playback","action":"seek","position_s":"3"})").find("must be a number") !=
        std::string::npos);
  CHECK(error_of(R"({"type":"playback","action":"play","position_s":3})").find("seek only") != std::string::npos);
  CHECK(error_of(std::string(40, '[') + std::string(40, ']')).find("nested deeper") != std::string::npos);
  CHECK(error_of(R"({"type":"request","id":1,"method":"POST","path":"/gifts","body":)" + std::string(100, '[') +
                 std::string(100, ']') + "}")
            .find("nested deeper") != std::string::npos);
  CHECK(error_of(std::string(tv::kMaxClientMessageBytes + 1, ' ')).find("larger than") != std::string::npos);
  // Brackets inside strings do not count as nesting.
  CHECK(error_of(R"({"type":"request","id":1,"method":"GET","path":"/)" + std::string(100, '[') + "\"}") ==
        "(accepted)");
}

TEST_CASE("viewer json: a refused request keeps its id when it had a usable one") {
  const tv::ClientMessage m = tv::parse_client_message(R"({"type":"request","id":12,"method":"get","path":"/x"})");
  const auto bad = as<tv::BadMessage>(m);
  REQUIRE(bad.id);
  CHECK(*bad.id == 12);
  const auto none = as<tv::BadMessage>(tv::parse_client_message(R"({"type":"request","id":-3})"));
  CHECK_FALSE(none.id);
  const auto unknown = as<tv::BadMessage>(tv::parse_client_message(R"({"type":"hello","id":4})"));
  REQUIRE(unknown.id);
  CHECK(*unknown.id == 4);
}
