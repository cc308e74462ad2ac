// Where the tests find the mocap clips: the shared recordings beside the
// checkout and the one bundled with the repository.
#pragma once

#include <string>

namespace tonus::balance::test {

inline std::string shared_clip(const std::string& name) { return std::string(TONUS_SHARED_DATA_DIR) + "/bvh/" + name; }
inline std::string bundled_clip(const std::string& name) {
  return std::string(TONUS_SOURCE_DIR) + "/tests/data/" + name;
}

}  // namespace tonus::balance::test
