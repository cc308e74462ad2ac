// The VRM file check (tonusd --vrm, viewer.vrm): what a usable glTF binary
// looks like from outside, and a one-line reason for everything else.
#include <doctest/doctest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tonus/host/viewer/vrm_file.hpp"
#include "vrm_files.hpp"

namespace tv = tonus::viewer;
namespace tt = tonus::viewer::testing;
namespace fs = std::filesystem;

namespace tonus::viewer::testing {

std::string glb_bytes(const std::string& json, std::uint32_t version, std::uint32_t stated_length) {
  std::string chunk = json;
  while (chunk.size() % 4 != 0) chunk += ' ';
  const auto le = [](std::uint32_t v) {
    std::string out(4, '\0');
    for (int i = 0; i < 4; ++i)
      out[static_cast<std::size_t>(i)] = static_cast<char>((v >> (8U * static_cast<unsigned>(i))) & 0xFFU);
    return out;
  };
  const auto length = static_cast<std::uint32_t>(12 + 8 + chunk.size());
  return "glTF" + le(version) + le(stated_length == 0 ? length : stated_length) +
         le(static_cast<std::uint32_t>(chunk.size())) + "JSON" + chunk;
}

void write_file(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << bytes;
}

TempDir::TempDir() {
  std::string pattern = (fs::temp_directory_path() / "tonus-vrm-XXXXXX").string();
  REQUIRE(mkdtemp(pattern.data()) != nullptr);
  path = pattern;
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path, ec);
}

}  // namespace tonus::viewer::testing

namespace {

const std::string kJson = R"({"asset":{"version":"2.0"},"extensionsUsed":["VRMC_vrm"]})";

}  // namespace

TEST_CASE("vrm file: a glTF binary, version 2, its stated length its own, under the cap, is usable") {
  tt::TempDir dir;
  const std::string bytes = tt::glb_bytes(kJson);
  tt::write_file(dir.path / "alice.vrm", bytes);
  const tv::VrmFileInfo info = tv::check_vrm_file(dir.path / "alice.vrm");
  CHECK_MESSAGE(info.error.empty(), info.error);
  CHECK(info.bytes == bytes.size());
  // The name does not matter: what is inside does.
  tt::write_file(dir.path / "alice.glb", bytes);
  CHECK(tv::check_vrm_file(dir.path / "alice.glb").error.empty());
}

TEST_CASE("vrm file: everything else is refused with a reason") {
  tt::TempDir dir;
  const std::string good = tt::glb_bytes(kJson);
  const auto reason = [&](const std::string& name, const std::string& bytes) {
    tt::write_file(dir.path / name, bytes);
    return tv::check_vrm_file(dir.path / name).error;
  };
  CHECK(tv::check_vrm_file(dir.path / "missing.vrm").error == "no such file");
  CHECK(tv::check_vrm_file("").error == "no file named");
  CHECK(tv::check_vrm_file(dir.path).error.find("a directory") != std::string::npos);
  CHECK(reason("empty.vrm", "").find("not a glTF binary") != std::string::npos);
  CHECK(reason("text.vrm", "{\"asset\":{\"version\":\"2.0\"}}").find("not a glTF binary") != std::string::npos);
  CHECK(reason("png.vrm", "\x89PNG\r\n\x1a\n....................").find("not a glTF binary") != std::string::npos);
  CHECK(reason("v1.vrm", tt::glb_bytes(kJson, 1)).find("version 1, only version 2") != std::string::npos);
  CHECK(reason("long.vrm", tt::glb_bytes(kJson, 2, 100000)).find("header says 100000 bytes") != std::string::npos);
  CHECK(reason("truncated.vrm", good.substr(0, good.size() - 8)).find("truncated or damaged") != std::string::npos);
  std::string bad_chunk = good;
  bad_chunk.replace(16, 4, std::string("BIN\0", 4));
  CHECK(reason("chunk.vrm", bad_chunk).find("not a JSON chunk") != std::string::npos);
  std::string huge_chunk = good;
  huge_chunk.replace(12, 4, std::string("\xff\xff\x00\x00", 4));
  CHECK(reason("overrun.vrm", huge_chunk).find("not a JSON chunk that fits") != std::string::npos);
  // A FIFO is not a regular file (and reading it would block).
  REQUIRE(mkfifo((dir.path / "fifo.vrm").c_str(), 0600) == 0);
  CHECK(tv::check_vrm_file(dir.path / "fifo.vrm").error == "not a regular file");
}

TEST_CASE("vrm file: over the size cap is refused before reading it") {
  tt::TempDir dir;
  // A sparse file past the default cap: no disk used, and its header would pass.
  const fs::path big = dir.path / "big.vrm";
  tt::write_file(big, tt::glb_bytes(kJson));
  fs::resize_file(big, tv::kMaxVrmBytes + 1);
  const std::string error = tv::check_vrm_file(big).error;
  CHECK(error.find("too large: 134217729 bytes, more than the 128 MiB the viewer serves") != std::string::npos);
  // A smaller cap, as a caller may pass.
  tt::write_file(dir.path / "small.vrm", tt::glb_bytes(kJson));
  CHECK(tv::check_vrm_file(dir.path / "small.vrm", 16).error.find("too large") != std::string::npos);
}
