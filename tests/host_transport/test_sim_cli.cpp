// tonus-band-sim on its own: the scripted scenarios and their JSON summary.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include "support/read_file.hpp"

using tonus::test::read_file;

namespace {

// The text of "key": <value> (array, object or scalar) in a flat JSON file.
std::string field(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": (\\[[^\\]]*\\]|\\{[^}]*\\}|[^,\\n]+)");
  std::smatch m;
  return std::regex_search(json, m, re) ? m[1].str() : std::string("<missing>");
}

std::string run_sim(const std::string& args, const std::string& json) {
  const std::string cmd = std::string(TONUS_BAND_SIM) + " " + args + " --json " + json + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  CHECK(::pclose(p) == 0);
  return out;
}

}  // namespace

TEST_CASE("sim CLI: rest, ramp and faults scenarios and their JSON summaries") {
  const std::string json =
      (std::filesystem::temp_directory_path() / ("tonus-sim-" + std::to_string(::getpid()) + ".json")).string();

  std::string out = run_sim("--synthetic rest --seconds 3 --fast", json);
  std::string j = read_file(json);
  const int rate_hz = std::stoi(field(j, "report_rate_hz"));  // the default report rate
  CHECK(rate_hz > 0);
  CHECK(out.find("reports " + std::to_string(3 * rate_hz)) != std::string::npos);
  CHECK(field(j, "reports") == std::to_string(3 * rate_hz));
  CHECK(field(j, "lost_blocks") == "0");
  CHECK(field(j, "levels_max") == "[0, 0, 0, 0]");
  CHECK(field(j, "flags_seen") ==
        "{\"electrode_off\": [], \"saturation\": [], \"artifact\": [], \"block_lost\": false}");

  run_sim("--synthetic ramp --seconds 5 --fast --seed 4", json);
  j = read_file(json);
  CHECK(field(j, "levels_min") == "[0, 0, 0, 0]");
  // Uncalibrated, so the top depends on each channel's gain; every group nearly saturates.
  std::stringstream maxima(field(j, "levels_max").substr(1));
  int groups = 0;
  for (std::string item; std::getline(maxima, item, ',');) {
    CHECK(std::stol(item) > 0.9 * 65535);
    ++groups;
  }
  CHECK(groups == 4);

  out = run_sim("--synthetic faults --seconds 5 --fast", json);
  j = read_file(json);
  CHECK(field(j, "lost_blocks") == "1");
  CHECK(field(j, "reports") == std::to_string(5 * rate_hz - 1));  // the lost 1 ms block cost one report
  CHECK(field(j, "sequence_continuous") == "true");
  CHECK(field(j, "flags_seen") ==
        "{\"electrode_off\": [2], \"saturation\": [5], \"artifact\": [0], \"block_lost\": true}");
  CHECK(out.find("electrode_off [2]") != std::string::npos);

  // Same seed, same run: the summary is reproducible byte for byte.
  run_sim("--synthetic faults --seconds 5 --fast", json + ".2");
  CHECK(read_file(json) == read_file(json + ".2"));
  std::filesystem::remove(json);
  std::filesystem::remove(json + ".2");
}

TEST_CASE("sim CLI: bad arguments are refused") {
  int rc = std::system((std::string(TONUS_BAND_SIM) + " --synthetic nope --seconds 1 2>/dev/null").c_str());
  CHECK(rc != 0);
  rc = std::system((std::string(TONUS_BAND_SIM) + " --synthetic rest 2>/dev/null").c_str());
  CHECK(rc != 0);
  rc = std::system((std::string(TONUS_BAND_SIM) + " --recording /nonexistent 2>/dev/null").c_str());
  CHECK(rc != 0);
  // A known device clock needs real time: the virtual clock of --fast has no host time to follow.
  rc = std::system(
      (std::string(TONUS_BAND_SIM) + " --synthetic rest --seconds 1 --fast --clock-offset-us 5 2>/dev/null").c_str());
  CHECK(rc != 0);
}
