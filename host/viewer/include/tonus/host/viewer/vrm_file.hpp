// The VRM avatar file a user points the viewer at (tonusd --vrm FILE,
// docs/viewer.md): checked when the daemon starts and again each time the
// page asks for it. Only its outer layer is checked here, cheaply and
// without parsing it: a glTF binary (GLB) container, version 2, whose stated
// length is the file's, starting with its JSON chunk, under a size cap. Whether
// it holds a VRM humanoid is for the page (three-vrm) to find out; a file it
// cannot use makes the page say so and keep the capsules.
//
// Compiled as C++17 and C++20 alike (the server's translation unit is C++17).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace tonus::viewer {

// The one URL the avatar is served at; the file is the configured one, never
// one a request names.
inline constexpr std::string_view kVrmUrl = "/avatar.vrm";
// VRoid Studio's exports are 10-40 MB; 4K textures can double that.
inline constexpr std::uintmax_t kMaxVrmBytes = std::uintmax_t{128} * 1024 * 1024;

struct VrmFileInfo {
  std::string error;         // empty: usable; else why not, one line (does not repeat the path)
  std::uintmax_t bytes = 0;  // the file's size when usable
};

// Checks `path` as described above. Never throws.
VrmFileInfo check_vrm_file(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxVrmBytes);

}  // namespace tonus::viewer
