// The server over real loopback sockets: round trips with the client,
// validation before the handler, limits, binding errors, hostile clients,
// stop() with clients connected, and curl as a third-party client.
#include <unistd.h>

#include <doctest/doctest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "control_fixtures.hpp"

namespace tc = tonus::control;
using tc::testing::RunningServer;
using Clock = std::chrono::steady_clock;

TEST_CASE("control server: every route round trips through the client") {
  RunningServer s;
  const tc::ControlClient c = s.client();

  const tc::ClientReply status = c.status();
  CHECK(status.ok());
  CHECK(status.status == 200);
  CHECK(status.body["state"] == "running");

  tc::GiftRequest gift;
  gift.kind = tc::GiftKind::cube;
  gift.bone = tonus::sim::Bone::RightHand;
  gift.mass_kg = 1.0;
  gift.size_m = 0.08;
  gift.height_m = 0.3;
  gift.lifetime_s = 10.0;
  const tc::ClientReply spawned = c.gift(gift);
  CHECK(spawned.status == 201);
  CHECK(spawned.body["id"] == 7);
  REQUIRE(s.handler.last_gift);
  CHECK(s.handler.last_gift->kind == tc::GiftKind::cube);
  CHECK(s.handler.last_gift->bone == tonus::sim::Bone::RightHand);
  CHECK(s.handler.last_gift->mass_kg == 1.0);
  CHECK(s.handler.last_gift->size_m == 0.08);
  CHECK(s.handler.last_gift->height_m == 0.3);
  CHECK(s.handler.last_gift->lifetime_s == 10.0);

  tc::GiftRequest ball;  // everything defaulted
  CHECK(c.gift(ball).status == 201);
  CHECK_FALSE(s.handler.last_gift->bone);
  CHECK_FALSE(s.handler.last_gift->mass_kg);

  CHECK(c.clear_gifts().ok());

  const tc::Levels levels{0.0, 0.5, 0.75, 1.0};
  const tc::ClientReply set = c.set_stiffness(levels);
  CHECK(set.ok());
  REQUIRE(s.handler.last_levels);
  CHECK(*s.handler.last_levels == levels);
  CHECK(c.set_stiffness(std::nullopt).ok());
  CHECK_FALSE(s.handler.last_levels->has_value());

  CHECK(c.calibrate(tc::CalibrationCommand::rest).status == 202);
  CHECK(s.handler.last_calibration == tc::CalibrationCommand::rest);
  CHECK(c.calibrate(tc::CalibrationCommand::mvc).status == 202);
  CHECK(s.handler.last_calibration == tc::CalibrationCommand::mvc);
  const tc::ClientReply abort = c.calibrate(tc::CalibrationCommand::abort);  // the handler's own error
  CHECK(abort.status == 409);
  CHECK(abort.error.empty());
  CHECK_FALSE(abort.ok());
  CHECK(abort.body["error"] == "no calibration running");

  CHECK(s.handler.calls() == std::vector<std::string>{"status", "spawn_gift", "spawn_gift", "clear_gifts",
                                                      "set_stiffness_override", "set_stiffness_override", "calibrate",
                                                      "calibrate", "calibrate"});
}

TEST_CASE("control server: invalid requests are refused with 400 naming the field, never reaching the handler") {
  RunningServer s;
  const tc::ControlClient c = s.client();
  struct Case {
    const char* method;
    const char* path;
    const char* body;
    const char* field;
  };
  const Case cases[] = {
      {"POST", "/gifts", "", "body"},
      {"POST", "/gifts", "{\"kind\":", "body"},
      {"POST", "/gifts", "[]", "body"},
      {"POST", "/gifts", R"({"kind":"anvil"})", "kind"},
      {"POST", "/gifts", R"({"kind":"ball","bone":"Tail"})", "bone"},
      {"POST", "/gifts", R"({"kind":"ball","mass_kg":20.5})", "mass_kg"},
      {"POST", "/gifts", R"({"kind":"ball","size_m":-0.1})", "size_m"},
      {"POST", "/gifts", R"({"kind":"ball","speed_mps":"fast"})", "speed_mps"},
      {"POST", "/gifts", R"({"kind":"cube","height_m":9})", "height_m"},
      {"POST", "/gifts", R"({"kind":"cube","lifetime_s":1e6})", "lifetime_s"},
      {"PUT", "/stiffness", "", "body"},
      {"PUT", "/stiffness", R"({"levels":[1,1,1]})", "levels"},
      {"PUT", "/stiffness", R"({"levels":[1,1,1,2]})", "levels[3]"},
      {"PUT", "/stiffness", R"({"level":null})", "level"},
  };
  for (const Case& k : cases) {
    CAPTURE(k.body);
    const tc::ClientReply r = c.request(k.method, k.path, k.body);
    CHECK(r.status == 400);
    CHECK(r.error.empty());
    CHECK(r.body["field"] == k.field);
    REQUIRE(r.body["error"].is_string());
    CHECK(r.body["error"].get<std::string>().rfind(std::string(k.field) + ":", 0) == 0);
  }
  // The value is named too.
  CHECK(
      c.request("POST", "/gifts", R"({"kind":"ball","mass_kg":20.5})").body["error"].get<std::string>().find("20.5") !=
      std::string::npos);
  CHECK(s.handler.call_count() == 0);
}

TEST_CASE("control server: unknown routes 404, wrong methods 405 with Allow") {
  RunningServer s;
  const tc::ControlClient c = s.client();
  CHECK(c.request("GET", "/nowhere").status == 404);
  CHECK(c.request("GET", "/nowhere").body["error"].get<std::string>().find("/nowhere") != std::string::npos);
  CHECK(c.request("POST", "/calibration/warmup").status == 404);
  CHECK(c.request("POST", "/status").status == 405);
  CHECK(c.request("GET", "/gifts").status == 405);
  CHECK(c.request("PATCH", "/gifts", "{}").status == 405);
  CHECK(c.request("DELETE", "/stiffness").status == 405);
  CHECK(c.request("GET", "/calibration/rest").status == 405);
  CHECK(c.request("OPTIONS", "/status").status == 405);

  const std::string reply = tc::testing::raw_exchange(s.port(), "POST /status HTTP/1.1\r\nHost: x\r\n\r\n");
  CHECK(tc::testing::raw_status(reply) == 405);
  CHECK(reply.find("Allow: GET, HEAD\r\n") != std::string::npos);
  CHECK(reply.find("Content-Type: application/json") != std::string::npos);

  const std::string head = tc::testing::raw_exchange(s.port(), "HEAD /status HTTP/1.1\r\nHost: x\r\n\r\n");
  CHECK(tc::testing::raw_status(head) == 200);
  CHECK(s.handler.calls() == std::vector<std::string>{"status"});
}

TEST_CASE("control server: a body over the limit is refused with 413") {
  RunningServer s;
  const tc::ControlClient c = s.client();
  std::string big = R"({"kind":"ball","pad":")";
  big.append(std::size_t{100} * 1024, 'x');
  big += "\"}";
  const tc::ClientReply r = c.request("POST", "/gifts", big);
  CHECK(r.status == 413);
  REQUIRE(r.body.is_object());
  CHECK(r.body["error"].get<std::string>().find("65536") != std::string::npos);
  // A large Content-Length announced, little sent: refused without reading it.
  const std::string raw =
      tc::testing::raw_exchange(s.port(), "PUT /stiffness HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\n{}");
  CHECK(tc::testing::raw_status(raw) == 413);
  CHECK(s.handler.call_count() == 0);
  CHECK(c.status().ok());
}

TEST_CASE("control server: handler exceptions and bad statuses become 500, the server stays up") {
  RunningServer s;
  const tc::ControlClient c = s.client();
  s.handler.throw_in_status = true;
  const tc::ClientReply r = c.status();
  CHECK(r.status == 500);
  CHECK(r.body["error"].get<std::string>().find("band unplugged") != std::string::npos);
  s.handler.throw_in_status = false;
  CHECK(c.status().ok());
}

TEST_CASE("control server: binding") {
  tc::testing::FakeHandler h;

  SUBCASE("a non-loopback address is refused without allow_remote, naming it") {
    tc::ControlServer server(h);
    for (const char* address : {"0.0.0.0", "::", "192.168.1.20", "example.com"}) {
      const std::string error = server.start(address, 0);
      CHECK(error.find(address) != std::string::npos);
      CHECK(error.find("allow_remote") != std::string::npos);
      CHECK_FALSE(server.running());
    }
  }

  SUBCASE("an address that is not this machine's fails cleanly even with allow_remote") {
    tc::ControlServer server(h);
    const std::string error = server.start("192.0.2.1", 0, true);  // TEST-NET-1: bind only, nothing is sent
    CHECK(error.find("192.0.2.1") != std::string::npos);
    CHECK_FALSE(server.running());
  }

  SUBCASE("bad ports") {
    tc::ControlServer server(h);
    CHECK(server.start("127.0.0.1", -1).find("-1") != std::string::npos);
    CHECK(server.start("127.0.0.1", 70000).find("70000") != std::string::npos);
    CHECK(server.start("", 0).find("empty") != std::string::npos);
  }

  SUBCASE("two servers on the same port: the second gets a clear error, the first keeps answering") {
    RunningServer first;
    tc::ControlServer second(h);
    const std::string error = second.start("127.0.0.1", first.port());
    CHECK(error.find("already in use") != std::string::npos);
    CHECK(error.find(std::to_string(first.port())) != std::string::npos);
    CHECK_FALSE(second.running());
    CHECK(first.client().status().ok());
    CHECK(h.call_count() == 0);
  }

  SUBCASE("start twice, restart after stop, stop twice") {
    tc::ControlServer server(h);
    REQUIRE(server.start("127.0.0.1", 0).empty());
    CHECK(server.running());
    CHECK(server.bind_address() == "127.0.0.1");
    CHECK(server.start("127.0.0.1", 0).find("already running") != std::string::npos);
    server.stop();
    CHECK_FALSE(server.running());
    CHECK(server.port() == 0);
    server.stop();
    REQUIRE(server.start("localhost", 0).empty());
    // localhost is 127.0.0.1 or ::1, whichever the resolver gives first.
    CHECK((tc::ControlClient("127.0.0.1", server.port()).status().ok() ||
           tc::ControlClient("::1", server.port()).status().ok()));
    server.stop();
  }

  SUBCASE("a stop() right after start() returns") {
    for (int i = 0; i < 20; ++i) {
      tc::ControlServer server(h);
      REQUIRE(server.start("127.0.0.1", 0).empty());
      server.stop();
    }
  }
}

TEST_CASE("control server: garbage and truncated requests do not take it down") {
  RunningServer s;
  using tc::testing::raw_exchange;
  using tc::testing::raw_status;
  const std::string garbage = raw_exchange(s.port(), "hello there\r\n\r\n");
  CHECK(raw_status(garbage) == 400);
  CHECK(garbage.find("\"error\"") != std::string::npos);
  std::string binary(2000, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>((i * 37U) & 0xFFU);
  raw_exchange(s.port(), binary, true);
  CHECK(raw_status(raw_exchange(s.port(), "PUT /stiffness HTTP/1.1\r\nHost: x\r\nContent-Length: -5\r\n\r\n")) >= 400);
  CHECK(raw_status(raw_exchange(s.port(), "POST /gifts HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n")) == 400);
  CHECK(raw_status(raw_exchange(s.port(), std::string("GET /") + std::string(20000, 'a') + " HTTP/1.1\r\n\r\n")) >=
        400);
  // No Content-Length: no body (curl -X POST sends none), answered at once.
  const auto t_bodiless = Clock::now();
  CHECK(raw_status(raw_exchange(s.port(), "PUT /stiffness HTTP/1.1\r\nHost: x\r\n\r\n")) == 400);
  CHECK(Clock::now() - t_bodiless < std::chrono::milliseconds(500));
  // Truncated: a body promised and not sent, the connection closed or left open.
  raw_exchange(s.port(), "POST /gifts HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n{\"kind\"", true,
               std::chrono::milliseconds(100));
  const int open_fd = tc::testing::connect_loopback(s.port());
  REQUIRE(open_fd >= 0);
  const std::string half = "PUT /stiffness HTTP/1.1\r\nHost: x\r\n";
  CHECK(::write(open_fd, half.data(), half.size()) == static_cast<ssize_t>(half.size()));

  const auto t0 = Clock::now();
  const tc::ClientReply r = s.client().status();
  CHECK(r.ok());
  CHECK(Clock::now() - t0 < std::chrono::seconds(3));
  ::close(open_fd);
  CHECK(s.handler.calls() == std::vector<std::string>{"status"});
}

TEST_CASE("control server: stop() with clients connected returns promptly") {
  RunningServer s;
  const int idle = tc::testing::connect_loopback(s.port());  // connected, sends nothing
  const int half = tc::testing::connect_loopback(s.port());  // sends half a request
  REQUIRE(idle >= 0);
  REQUIRE(half >= 0);
  const std::string partial = "POST /gifts HTTP/1.1\r\nContent-Length: 50\r\n\r\n{";
  CHECK(::write(half, partial.data(), partial.size()) == static_cast<ssize_t>(partial.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // both taken by the workers
  const auto t0 = Clock::now();
  s.server->stop();
  const auto took = Clock::now() - t0;
  MESSAGE("stop() took " << std::chrono::duration_cast<std::chrono::milliseconds>(took).count() << " ms");
  CHECK(took < std::chrono::milliseconds(2500));
  CHECK_FALSE(s.server->running());
  ::close(idle);
  ::close(half);
  CHECK(s.handler.call_count() == 0);
}

TEST_CASE("control server: handler calls are serialized") {
  RunningServer s;
  s.handler.delay = std::chrono::milliseconds(30);
  std::vector<std::thread> clients;
  clients.reserve(6);
  std::atomic<int> ok{0};
  for (int i = 0; i < 6; ++i) {
    clients.emplace_back([&] {
      if (s.client().status().ok()) ++ok;
    });
  }
  for (std::thread& t : clients) t.join();
  CHECK(ok == 6);
  CHECK(s.handler.max_concurrent == 1);
}

TEST_CASE("control client: a daemon that is not there is an error naming host:port, not an exception") {
  const int port = tc::testing::free_port();
  REQUIRE(port > 0);
  const tc::ClientReply r = tc::ControlClient("127.0.0.1", port, 1.0).status();
  CHECK(r.status == 0);
  CHECK_FALSE(r.reached());
  CHECK_FALSE(r.ok());
  CHECK(r.error.find("127.0.0.1:" + std::to_string(port)) != std::string::npos);
}

namespace {

// Runs a command, returns its stdout.
std::string run(const std::string& command) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) return out;
  char buf[512];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

}  // namespace

TEST_CASE("control server: curl as a third-party client") {
  const char* curl = "/usr/bin/curl";
  if (!std::filesystem::exists(curl)) {
    MESSAGE("skipped: " << curl << " is not installed");
    return;
  }
  RunningServer s;
  const std::string base = std::string(curl) + " -s --max-time 5 -w ' %{http_code}' ";
  const std::string url = "http://127.0.0.1:" + std::to_string(s.port());

  const std::string status = run(base + url + "/status");
  CHECK(status.find("\"state\":\"running\"") != std::string::npos);
  CHECK(status.substr(status.size() - 4) == " 200");

  const std::string gift = run(base + "-H 'Content-Type: application/json' -d '{\"kind\":\"ball\",\"bone\":\"Chest\"," +
                               "\"speed_mps\":9}' " + url + "/gifts");
  CHECK(gift.substr(gift.size() - 4) == " 201");
  REQUIRE(s.handler.last_gift);
  CHECK(s.handler.last_gift->bone == tonus::sim::Bone::Chest);
  CHECK(s.handler.last_gift->speed_mps == 9.0);

  // curl -d without a Content-Type header sends form encoding; the body is JSON all the same.
  const std::string stiff = run(base + "-X PUT -d '{\"levels\":[0.2,0.4,0.6,0.8]}' " + url + "/stiffness");
  CHECK(stiff.substr(stiff.size() - 4) == " 200");
  REQUIRE(s.handler.last_levels);
  CHECK(*s.handler.last_levels == tc::Levels{0.2, 0.4, 0.6, 0.8});

  const std::string bad = run(base + "-X PUT -d '{\"levels\":[0.2,0.4,0.6]}' " + url + "/stiffness");
  CHECK(bad.substr(bad.size() - 4) == " 400");
  CHECK(bad.find("levels") != std::string::npos);

  CHECK(run(base + "-X DELETE " + url + "/gifts").find(" 200") != std::string::npos);
  CHECK(run(base + "-X POST " + url + "/calibration/mvc").find(" 202") != std::string::npos);
  CHECK(run(base + "-X POST " + url + "/calibration/abort").find(" 409") != std::string::npos);
  CHECK(run(base + url + "/gifts").find(" 405") != std::string::npos);
  CHECK(run(base + url + "/elsewhere").find(" 404") != std::string::npos);
}
