// tonusd's configuration: defaults that validate, every error naming its key
// and value, unknown keys refused, and the printed config reading back the same.
#include <doctest/doctest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tonus/host/daemon/config_file.hpp"
#include "tonus/host/viewer/vrm_file.hpp"

using namespace tonus::daemon;

namespace {

std::string parse(const std::string& text) {
  DaemonConfig c;
  return parse_config(text, "test.toml", c);
}

}  // namespace

TEST_CASE("config: the defaults validate and match the issue's ports") {
  const DaemonConfig c;
  CHECK(validate(c).empty());
  CHECK(c.tracker.listen_port == 39540);
  CHECK(c.output.host == "127.0.0.1");
  CHECK(c.output.port == 39539);
  CHECK(c.output.rate_hz == 60.0);
  CHECK(c.control.address == "127.0.0.1");
  CHECK_FALSE(c.control.allow_remote);
  CHECK(c.physics.rate_hz == 1000.0);
  CHECK(c.band.stiffness.stale_after_s == 0.1);
}

TEST_CASE("config: a bad value names the key and the value, and nothing is accepted") {
  const struct {
    const char* text;
    const char* expect;
  } cases[] = {
      {"[output]\nrate_hz = 500\n", "output.rate_hz = 500: must be 1..200"},
      {"[output]\nport = 0\n", "output.port = 0"},
      {"[output]\nport = \"39539\"\n", "output.port = \"39539\": must be an integer"},
      {"[physics]\nrate_hz = 10\n", "physics.rate_hz = 10"},
      {"[physics]\nfeedforward = \"magic\"\n", "physics.feedforward = \"magic\": must be one of simulation"},
      {"[band]\nsource = \"usb\"\n", "band.source = \"usb\""},
      {"[band]\nsafe_stiffness = 1.5\n", "band.safe_stiffness = 1.5"},
      {"[band]\nsafe_stiffness = [0.1, 0.2]\n", "band.safe_stiffness = [0.1, 0.2]: must be a number or an array of 4"},
      {"[band]\ncan_node = 40\n", "band.can_node = 40"},
      {"[band]\nsource = \"candump\"\n", "band.candump_path = \"\""},
      {"[band]\nsource = \"socket\"\n", "band.sim_socket = \"\""},
      {"[band]\nstale_after_ms = -5\n", "band.stale_after_ms = -5"},
      {"[tracker]\nlisten_port = 70000\n", "tracker.listen_port = 70000"},
      {"[tracker]\ndelay_ms = 5000\n", "tracker.delay_ms = 5000"},
      {"[tracker]\nbalance = \"on\"\n", "tracker.balance = \"on\": must be one of off, offline, online"},
      {"[tracker]\nbalance_lookahead_ms = 400\n", "tracker.balance_lookahead_ms = 400: must be 1..250"},
      {"[tracker]\nsource = \"vmc\"\nvmc_mode = \"trackers\"\nbalance = \"online\"\n",
       "tracker.balance = \"online\": the balance filter runs on a bvh source or a VMC performer stream"},
      {"[tracker]\nsource = \"vmc\"\nbalance = \"offline\"\n",
       "tracker.balance = \"offline\": the offline filter needs a whole clip"},
      {"[log]\nlevel = \"loud\"\n", "log.level = \"loud\""},
      {"[demo]\ngifts = [ { at_s = 1, kind = \"piano\", bone = \"Head\" } ]\n", "demo.gifts[0].kind = \"piano\""},
      {"[demo]\ngifts = [ { at_s = 1, kind = \"ball\", bone = \"Tail\" } ]\n", "demo.gifts[0].bone = \"Tail\""},
      {"[demo]\ngifts = [ { at_s = 1, kind = \"ball\", bone = \"Head\", colour = 3 } ]\n",
       "demo.gifts[0].colour: unknown key"},
      {"[output]\nrat_hz = 60\n", "output.rat_hz: unknown key"},
      {"[outptu]\nport = 1\n", "outptu: unknown table"},
      {"[output\nport = 1\n", "test.toml:1:"},  // a syntax error, with its line
  };
  for (const auto& c : cases) {
    const std::string e = parse(c.text);
    INFO(std::string(c.text));
    INFO(e);
    CHECK(e.find(c.expect) != std::string::npos);
    CHECK(e.rfind("test.toml", 0) == 0);  // names the file too
  }
  DaemonConfig c;
  CHECK(load_config("/nonexistent/tonusd.toml", c).find("cannot open") != std::string::npos);
}

TEST_CASE("config: keys read over the defaults, the printed config reads back to the same values") {
  DaemonConfig c;
  REQUIRE(parse_config("[band]\nsource = \"can\"\ncan_interface = \"vcan0\"\nsafe_stiffness = [0.1, 0.2, 0.3, 0.4]\n"
                       "sim_args = [\"--swell-period\", \"7\"]\n"
                       "[output]\nrate_hz = 90\nbundle = false\n[tracker]\nsource = \"vmc\"\nvmc_mode = \"trackers\"\n"
                       "[demo]\ngifts = [ { at_s = 2.5, kind = \"ball\", bone = \"Head\" } ]\n",
                       "a.toml", c)
              .empty());
  CHECK(c.band.source == BandSource::can);
  CHECK(c.band.can_interface == "vcan0");
  CHECK(c.band.stiffness.safe_default[3] == 0.4);
  CHECK(c.band.sim_args.size() == 2);
  CHECK(c.output.rate_hz == 90.0);
  CHECK_FALSE(c.output.bundle);
  CHECK(c.tracker.vmc_mode == VmcMode::trackers);
  REQUIRE(c.demo.gifts.size() == 1);
  CHECK(c.demo.gifts[0].bone == "Head");
  CHECK(c.output.port == 39539);  // untouched keys keep their defaults
  CHECK(c.tracker.balance == tonus::balance::BalanceMode::off);
  REQUIRE(parse_config("[tracker]\nsource = \"bvh\"\nbalance = \"online\"\nbalance_lookahead_ms = 100\n", "b.toml", c)
              .empty());
  CHECK(c.tracker.balance == tonus::balance::BalanceMode::online);
  CHECK(c.tracker.balance_lookahead_s == doctest::Approx(0.1));
  DaemonConfig live;
  REQUIRE(parse_config("[tracker]\nsource = \"vmc\"\nbalance = \"online\"\n", "v.toml", live).empty());
  CHECK(live.tracker.balance == tonus::balance::BalanceMode::online);  // a live performer: online only

  const std::string printed = to_toml(c);
  DaemonConfig back;
  INFO(printed);
  REQUIRE(parse_config(printed, "printed", back).empty());
  CHECK(to_toml(back) == printed);
  CHECK(back.band.stiffness.safe_default == c.band.stiffness.safe_default);
  CHECK(back.band.stiffness.stale_after_s == doctest::Approx(c.band.stiffness.stale_after_s));
  CHECK(back.demo.gifts[0].at_s == 2.5);
  CHECK(back.band.sim_args == c.band.sim_args);
  CHECK(back.tracker.balance == tonus::balance::BalanceMode::online);
  CHECK(back.tracker.balance_lookahead_s == doctest::Approx(0.1));
}

namespace {

// A glTF binary with one JSON chunk, as a .vrm starts.
std::string glb(const std::string& json) {
  const auto le = [](std::uint32_t v) {
    std::string out(4, '\0');
    for (std::size_t i = 0; i < 4; ++i) out[i] = static_cast<char>((v >> (8U * i)) & 0xFFU);
    return out;
  };
  std::string chunk = json;
  while (chunk.size() % 4 != 0) chunk += ' ';
  return "glTF" + le(2) + le(static_cast<std::uint32_t>(20 + chunk.size())) +
         le(static_cast<std::uint32_t>(chunk.size())) + "JSON" + chunk;
}

}  // namespace

TEST_CASE("config: viewer.vrm is read and printed, and its file checked only by check_files") {
  std::string pattern = (std::filesystem::temp_directory_path() / "tonus-config-vrm-XXXXXX").string();
  REQUIRE(mkdtemp(pattern.data()) != nullptr);
  const std::filesystem::path dir = pattern;
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return (dir / name).string();
  };
  const std::string good = write("alice.vrm", glb(R"({"asset":{"version":"2.0"}})"));
  const std::string text = write("text.vrm", "{\"asset\":{}}");
  const std::string big = write("big.vrm", glb("{}"));
  std::filesystem::resize_file(big, tonus::viewer::kMaxVrmBytes + 1);  // sparse: no disk used

  DaemonConfig c;
  REQUIRE(parse_config("[viewer]\nvrm = \"" + good + "\"\n", "a.toml", c).empty());
  CHECK(c.viewer.vrm == good);
  CHECK(check_files(c).empty());
  DaemonConfig back;
  REQUIRE(parse_config(to_toml(c), "printed", back).empty());
  CHECK(back.viewer.vrm == good);
  CHECK(DaemonConfig{}.viewer.vrm.empty());  // no avatar by default
  CHECK(check_files(DaemonConfig{}).empty());

  // validate() looks at values only (a recording's config validates anywhere); check_files opens the file.
  const struct {
    std::string path;
    std::string expect;
  } cases[] = {
      {"/nonexistent/alice.vrm", "viewer.vrm = \"/nonexistent/alice.vrm\": no such file"},
      {dir.string(), "a directory"},
      {text, "not a glTF binary"},
      {big, "too large"},
  };
  for (const auto& k : cases) {
    c.viewer.vrm = k.path;
    INFO(k.path);
    CHECK(validate(c).empty());
    const std::string e = check_files(c);
    INFO(e);
    CHECK(e.rfind("viewer.vrm = \"" + k.path + "\": ", 0) == 0);
    CHECK(e.find(k.expect) != std::string::npos);
  }
  c.viewer.enabled = false;  // no viewer, no avatar to check
  CHECK(check_files(c).empty());
  std::filesystem::remove_all(dir);
}
