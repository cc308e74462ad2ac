// Parsing, validation and routing without sockets.
#include <doctest/doctest.h>

#include <string>

#include "control_fixtures.hpp"
#include "tonus/host/control/requests.hpp"
#include "tonus/host/control/router.hpp"

namespace tc = tonus::control;
using tc::testing::FakeHandler;

namespace {

tc::Invalid gift_invalid(const std::string& body) {
  auto r = tc::parse_gift_request(body);
  REQUIRE_MESSAGE(std::holds_alternative<tc::Invalid>(r), body);
  return std::get<tc::Invalid>(r);
}

tc::Invalid stiffness_invalid(const std::string& body) {
  auto r = tc::parse_stiffness_request(body);
  REQUIRE_MESSAGE(std::holds_alternative<tc::Invalid>(r), body);
  return std::get<tc::Invalid>(r);
}

}  // namespace

TEST_CASE("control: a full gift request parses") {
  auto r = tc::parse_gift_request(
      R"({"kind":"cube","bone":"LeftHand","mass_kg":1.5,"size_m":0.1,"height_m":0.4,"lifetime_s":0})");
  REQUIRE(std::holds_alternative<tc::GiftRequest>(r));
  const auto& g = std::get<tc::GiftRequest>(r);
  CHECK(g.kind == tc::GiftKind::cube);
  CHECK(g.bone == tonus::sim::Bone::LeftHand);
  CHECK(g.mass_kg == 1.5);
  CHECK(g.size_m == 0.1);
  CHECK(g.height_m == 0.4);
  CHECK(g.lifetime_s == 0.0);
  CHECK_FALSE(g.speed_mps);
}

TEST_CASE("control: absent, null and empty fields are the kind's defaults") {
  auto r = tc::parse_gift_request(R"({"kind":"ball","bone":"","mass_kg":null})");
  REQUIRE(std::holds_alternative<tc::GiftRequest>(r));
  const auto& g = std::get<tc::GiftRequest>(r);
  CHECK(g.kind == tc::GiftKind::ball);
  CHECK_FALSE(g.bone);
  CHECK_FALSE(g.mass_kg);
}

TEST_CASE("control: every one of the 21 bones is accepted by name") {
  for (const auto& b : tonus::sim::kBones) {
    auto r = tc::parse_gift_request(R"({"kind":"ball","bone":")" + std::string(b.name) + "\"}");
    REQUIRE(std::holds_alternative<tc::GiftRequest>(r));
    CHECK(std::get<tc::GiftRequest>(r).bone == b.bone);
  }
}

TEST_CASE("control: gift validation names the field and the value") {
  struct Case {
    const char* body;
    const char* field;
    const char* mentions;
  };
  const Case cases[] = {
      {"", "body", "empty"},
      {"{", "body", "not valid JSON"},
      {"[1,2]", "body", "an array"},
      {"\"ball\"", "body", "\"ball\""},
      {R"({"kind":"ball","mass_kg":1e999})", "body", "overflow"},
      {"{}", "kind", "required"},
      {R"({"kind":3})", "kind", "3"},
      {R"({"kind":"pyramid"})", "kind", "\"pyramid\""},
      {R"({"kind":"ball","bone":"Hand"})", "bone", "\"Hand\""},
      {R"({"kind":"ball","bone":"righthand"})", "bone", "RightHand"},  // the list of names
      {R"({"kind":"ball","bone":7})", "bone", "7"},
      {R"({"kind":"ball","mass_kg":25})", "mass_kg", "25"},
      {R"({"kind":"ball","mass_kg":0})", "mass_kg", "0.01..20"},
      {R"({"kind":"ball","mass_kg":"1"})", "mass_kg", "\"1\""},
      {R"({"kind":"ball","mass_kg":true})", "mass_kg", "true"},
      {R"({"kind":"ball","size_m":2})", "size_m", "2"},
      {R"({"kind":"ball","size_m":0.001})", "size_m", "0.001"},
      {R"({"kind":"ball","speed_mps":41})", "speed_mps", "41"},
      {R"({"kind":"ball","speed_mps":-1})", "speed_mps", "-1"},
      {R"({"kind":"cube","height_m":3.5})", "height_m", "3.5"},
      {R"({"kind":"cube","lifetime_s":601})", "lifetime_s", "601"},
      {R"({"kind":"ball","lifetime_s":[1]})", "lifetime_s", "an array"},
      {R"({"kind":"cube","speed_mps":3})", "speed_mps", "ball only"},
      {R"({"kind":"ball","height_m":1})", "height_m", "cube only"},
      {R"({"kind":"ball","mass":1})", "mass", "unknown field"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.body);
    const tc::Invalid bad = gift_invalid(c.body);
    CHECK(bad.field == c.field);
    CHECK(bad.message.rfind(std::string(c.field) + ":", 0) == 0);
    CHECK_MESSAGE(bad.message.find(c.mentions) != std::string::npos, bad.message);
  }
}

TEST_CASE("control: stiffness bodies") {
  auto set = tc::parse_stiffness_request(R"({"levels":[0,0.25,0.5,1]})");
  REQUIRE(std::holds_alternative<std::optional<tc::Levels>>(set));
  CHECK(std::get<std::optional<tc::Levels>>(set) == tc::Levels{0.0, 0.25, 0.5, 1.0});
  auto release = tc::parse_stiffness_request(R"({"levels":null})");
  REQUIRE(std::holds_alternative<std::optional<tc::Levels>>(release));
  CHECK_FALSE(std::get<std::optional<tc::Levels>>(release).has_value());

  struct Case {
    const char* body;
    const char* field;
    const char* mentions;
  };
  const Case cases[] = {
      {"{}", "levels", "required"},
      {"nope", "body", "not valid JSON"},
      {R"({"levels":"high"})", "levels", "\"high\""},
      {R"({"levels":[0.1,0.2,0.3]})", "levels", "got 3"},
      {R"({"levels":[0.1,0.2,0.3,0.4,0.5]})", "levels", "got 5"},
      {R"({"levels":[0,0,0,1.5]})", "levels[3]", "1.5"},
      {R"({"levels":[0,0,-0.1,0]})", "levels[2]", "-0.1"},
      {R"({"levels":[0,"a",0,0]})", "levels[1]", "\"a\""},
      {R"({"levels":[null,0,0,0]})", "levels[0]", "null"},
      {R"({"levels":null,"x":1})", "x", "unknown field"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.body);
    const tc::Invalid bad = stiffness_invalid(c.body);
    CHECK(bad.field == c.field);
    CHECK_MESSAGE(bad.message.find(c.mentions) != std::string::npos, bad.message);
  }
}

TEST_CASE("control: what the client sends, the server accepts") {
  tc::GiftRequest g;
  g.kind = tc::GiftKind::ball;
  g.bone = tonus::sim::Bone::Head;
  g.speed_mps = 12.0;
  g.lifetime_s = 3.0;
  auto back = tc::parse_gift_request(tc::to_json(g).dump());
  REQUIRE(std::holds_alternative<tc::GiftRequest>(back));
  const auto& b = std::get<tc::GiftRequest>(back);
  CHECK(b.kind == g.kind);
  CHECK(b.bone == g.bone);
  CHECK(b.speed_mps == g.speed_mps);
  CHECK(b.lifetime_s == g.lifetime_s);
  CHECK_FALSE(b.mass_kg);

  const tc::Levels levels{0.1, 0.2, 0.3, 0.4};
  auto s = tc::parse_stiffness_request(tc::stiffness_body(levels).dump());
  REQUIRE(std::holds_alternative<std::optional<tc::Levels>>(s));
  CHECK(std::get<std::optional<tc::Levels>>(s) == levels);
}

TEST_CASE("control: routing: 404, 405 with Allow, HEAD as GET, handler failures") {
  FakeHandler h;
  CHECK(tc::route(h, "GET", "/nope", "").reply.status == 404);
  CHECK(tc::route(h, "GET", "/", "").reply.status == 404);
  CHECK(tc::route(h, "POST", "/calibration/warmup", "").reply.status == 404);
  CHECK(tc::route(h, "POST", "/calibration/", "").reply.status == 404);
  CHECK(tc::route(h, "POST", "/status/", "").reply.status == 404);

  struct Case {
    const char* method;
    const char* path;
    const char* allow;
  };
  const Case cases[] = {{"POST", "/status", "GET, HEAD"},      {"GET", "/gifts", "POST, DELETE"},
                        {"PUT", "/gifts", "POST, DELETE"},     {"GET", "/stiffness", "PUT"},
                        {"POST", "/stiffness", "PUT"},         {"GET", "/calibration/rest", "POST"},
                        {"DELETE", "/calibration/mvc", "POST"}};
  for (const Case& c : cases) {
    CAPTURE(c.path);
    const tc::Routed r = tc::route(h, c.method, c.path, "");
    CHECK(r.reply.status == 405);
    CHECK(r.allow == c.allow);
    CHECK(r.reply.body["error"].get<std::string>().find(c.method) != std::string::npos);
  }
  CHECK(h.call_count() == 0);

  CHECK(tc::route(h, "HEAD", "/status", "").reply.status == 200);
  h.throw_in_status = true;
  const tc::Routed thrown = tc::route(h, "GET", "/status", "");
  CHECK(thrown.reply.status == 500);
  CHECK(thrown.reply.body["error"].get<std::string>().find("band unplugged") != std::string::npos);
  h.throw_in_status = false;
  h.status_code = 42;
  CHECK(tc::route(h, "GET", "/status", "").reply.status == 500);
}

TEST_CASE("control: loopback addresses") {
  CHECK(tc::is_loopback_address("127.0.0.1"));
  CHECK(tc::is_loopback_address("127.1.2.3"));
  CHECK(tc::is_loopback_address("::1"));
  CHECK(tc::is_loopback_address("::ffff:127.0.0.1"));
  CHECK(tc::is_loopback_address("localhost"));
  CHECK(tc::is_loopback_address("LocalHost"));
  CHECK_FALSE(tc::is_loopback_address("0.0.0.0"));
  CHECK_FALSE(tc::is_loopback_address("::"));
  CHECK_FALSE(tc::is_loopback_address("192.168.1.10"));
  CHECK_FALSE(tc::is_loopback_address("128.0.0.1"));
  CHECK_FALSE(tc::is_loopback_address("example.com"));
  CHECK_FALSE(tc::is_loopback_address("127.0.0.1.example.com"));
  CHECK_FALSE(tc::is_loopback_address(""));
}
