// The page's files: which file an HTTP request target names under the web
// root, and its MIME type. No sockets here; the server (server.hpp) serves
// what this resolves, and the tests check it directly too.
//
// Layout (docs/viewer.md):
//   /                          -> WEB_ROOT/index.html
//   /vendor/three/addons/X     -> WEB_ROOT/node_modules/three/examples/jsm/X
//   /vendor/three/X            -> WEB_ROOT/node_modules/three/build/X
//   /vendor/three-vrm/X        -> WEB_ROOT/node_modules/@pixiv/three-vrm/lib/X
//   /X                         -> WEB_ROOT/X  (not node_modules/ itself)
// Refused: "." and ".." segments (also percent-encoded), hidden files (a
// segment starting with '.'), backslashes, NUL and control characters, bad
// percent escapes, and anything whose real path (symlinks followed) leaves
// its base folder.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace tonus::viewer {

// The source tree's host/viewer/web (a compile definition of this library).
std::string default_web_root();

struct StaticTarget {
  int status = 404;            // 200: `file` is a regular file to serve
  std::filesystem::path file;  // when 200
  std::string error;           // otherwise: a one-line reason for the reply's body
};

// Resolves an HTTP request target ("/js/main.js?v=2") under `web_root`.
// Statuses: 200, 400 (malformed target), 403 (traversal, hidden or private
// file), 404 (no such file, or three.js not installed: the error says to run
// scripts/install-deps.sh).
StaticTarget resolve_static(const std::filesystem::path& web_root, std::string_view target);

// Decodes %XX escapes (not '+': this is a path); nullopt for a malformed escape.
std::optional<std::string> percent_decode(std::string_view text);

// "text/javascript; charset=utf-8" for .js, ...; application/octet-stream when unknown.
std::string_view mime_type(const std::filesystem::path& file);

// The message a page shows (and a 404 carries) when three.js is missing.
inline constexpr std::string_view kThreeMissing = "three.js is not installed: run scripts/install-deps.sh";
// The same for three-vrm (only a page with a VRM avatar needs it).
inline constexpr std::string_view kThreeVrmMissing = "three-vrm is not installed: run scripts/install-deps.sh";

}  // namespace tonus::viewer
