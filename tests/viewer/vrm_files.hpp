// GLB files for the VRM tests (C++ side): a minimal well-formed container
// and ways to damage it. The browser tests' real avatars come from
// make_vrm.mjs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace tonus::viewer::testing {

// A glTF binary: header (magic, version, length) and one JSON chunk.
// `stated_length` 0: the true length.
std::string glb_bytes(const std::string& json, std::uint32_t version = 2, std::uint32_t stated_length = 0);

// Writes `bytes` to `file` (creating its folder).
void write_file(const std::filesystem::path& file, const std::string& bytes);

// A fresh temporary folder, removed with its content at the end.
struct TempDir {
  std::filesystem::path path;
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  TempDir(TempDir&&) = delete;
  TempDir& operator=(TempDir&&) = delete;
};

}  // namespace tonus::viewer::testing
