// A directory of the test process's own under the system's temporary
// directory, removed with everything in it when the process exits, so test
// files (logs, JSON summaries, sockets, written clips) never pile up there.
// A process killed by a timeout leaves its directory for the post-mortem.
#pragma once

#include <filesystem>
#include <string>

namespace tonus::test {

// Created on first use (mkdtemp: tonus-test-XXXXXX); empty when it cannot be.
const std::filesystem::path& scratch_dir();

// `name` inside scratch_dir().
inline std::string scratch_path(const std::string& name) { return (scratch_dir() / name).string(); }

}  // namespace tonus::test
