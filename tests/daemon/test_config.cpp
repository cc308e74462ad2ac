// tonusd's configuration: defaults that validate, every error naming its key
// and value, unknown keys refused, and the printed config reading back the same.
#include <doctest/doctest.h>

#include "tonus/host/daemon/config_file.hpp"

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

  const std::string printed = to_toml(c);
  DaemonConfig back;
  INFO(printed);
  REQUIRE(parse_config(printed, "printed", back).empty());
  CHECK(to_toml(back) == printed);
  CHECK(back.band.stiffness.safe_default == c.band.stiffness.safe_default);
  CHECK(back.band.stiffness.stale_after_s == doctest::Approx(c.band.stiffness.stale_after_s));
  CHECK(back.demo.gifts[0].at_s == 2.5);
  CHECK(back.band.sim_args == c.band.sim_args);
}
