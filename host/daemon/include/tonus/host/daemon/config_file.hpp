// tonusd's TOML configuration file (toml++): read into a DaemonConfig over
// its defaults, and the effective configuration printed back as TOML
// (`tonusd --print-config`). Unknown tables and keys are errors (a typo must
// not silently fall back to a default), as are wrong types; every error names
// the key and the value.
#pragma once

#include <string>
#include <string_view>

#include "tonus/host/daemon/config.hpp"

namespace tonus::daemon {

// Reads `text` (the file's content; `source` names it in messages) over the
// values already in `config`, then validates the result. Empty on success,
// else the error (and `config` is unspecified).
std::string parse_config(std::string_view text, std::string_view source, DaemonConfig& config);

// Reads the file at `path` the same way; a missing or unreadable file is an error.
std::string load_config(const std::string& path, DaemonConfig& config);

// The configuration as a TOML document that parse_config reads back to the same values.
std::string to_toml(const DaemonConfig& config);

}  // namespace tonus::daemon
