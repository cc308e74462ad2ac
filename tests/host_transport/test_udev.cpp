// The udev rule in packaging/udev names the ids the firmware enumerates with,
// and its install script puts it where udev reads rules.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "support/read_file.hpp"
#include "tonus/usb/descriptors.hpp"

using tonus::test::read_file;

namespace {}  // namespace

TEST_CASE("udev rule: matches the band's hidraw node by the firmware's VID:PID") {
  std::ifstream in(TONUS_UDEV_DIR "/70-tonus-band.rules");
  REQUIRE(in);
  int rules = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    ++rules;
    std::smatch m;
    REQUIRE(std::regex_search(line, m, std::regex(R"re(ATTRS\{idVendor\}=="([0-9a-fA-F]{4})")re")));
    CHECK(std::stoul(m[1].str(), nullptr, 16) == tonus::usb::kVendorId);
    REQUIRE(std::regex_search(line, m, std::regex(R"re(ATTRS\{idProduct\}=="([0-9a-fA-F]{4})")re")));
    CHECK(std::stoul(m[1].str(), nullptr, 16) == tonus::usb::kProductId);
    // udev compares these as strings: sysfs writes them as four lower-case hex digits.
    CHECK(m[1].str() == std::regex_replace(m[1].str(), std::regex("[A-F]"), "x"));
    CHECK(line.find(R"(SUBSYSTEM=="hidraw")") != std::string::npos);
    CHECK(line.find(R"(MODE="0660")") != std::string::npos);
    CHECK(line.find(R"(TAG+="uaccess")") != std::string::npos);
  }
  CHECK(rules == 1);
}

TEST_CASE("udev rule: the install script puts it under rules.d") {
  const auto root = std::filesystem::temp_directory_path() / ("tonus-udev-" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  const std::string cmd = "DESTDIR=" + root.string() + " sh " TONUS_UDEV_DIR "/install.sh >/dev/null";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const auto installed = root / "etc/udev/rules.d/70-tonus-band.rules";
  CHECK(read_file(installed.string()) == read_file(TONUS_UDEV_DIR "/70-tonus-band.rules"));
  CHECK((std::filesystem::status(installed).permissions() & std::filesystem::perms::others_write) ==
        std::filesystem::perms::none);
  std::filesystem::remove_all(root);
}
