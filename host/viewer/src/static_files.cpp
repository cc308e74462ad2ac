#include "tonus/host/viewer/static_files.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <system_error>
#include <utility>
#include <vector>

#ifndef TONUS_VIEWER_WEB_ROOT
#error "TONUS_VIEWER_WEB_ROOT must be defined (host/viewer/CMakeLists.txt)"
#endif

namespace tonus::viewer {

namespace fs = std::filesystem;

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

StaticTarget refuse(int status, std::string error) {
  StaticTarget t;
  t.status = status;
  t.error = std::move(error);
  return t;
}

// True when `path` (canonical) is `base` (canonical) or inside it.
bool is_within(const fs::path& path, const fs::path& base) {
  auto p = path.begin();
  for (auto b = base.begin(); b != base.end(); ++b, ++p) {
    if (p == path.end() || *p != *b) return false;
  }
  return true;
}

struct Mount {
  std::string_view prefix;   // URL prefix, ends with '/'
  std::string_view folder;   // under the web root
  std::string_view missing;  // the install hint when the folder is missing
};

// Longest prefix first.
constexpr std::array<Mount, 3> kMounts{{
    {"/vendor/three/addons/", "node_modules/three/examples/jsm", kThreeMissing},
    {"/vendor/three/", "node_modules/three/build", kThreeMissing},
    {"/vendor/three-vrm/", "node_modules/@pixiv/three-vrm/lib", kThreeVrmMissing},
}};

}  // namespace

std::string default_web_root() { return TONUS_VIEWER_WEB_ROOT; }

std::optional<std::string> percent_decode(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 2 >= text.size()) return std::nullopt;
    const int hi = hex_value(text[i + 1]);
    const int lo = hex_value(text[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return out;
}

StaticTarget resolve_static(const fs::path& web_root, std::string_view target) {
  // The path part: no query or fragment.
  std::string_view raw = target.substr(0, target.find_first_of("?#"));
  if (raw.empty() || raw.front() != '/') return refuse(400, "the request target must start with '/'");
  const auto decoded = percent_decode(raw);
  if (!decoded) return refuse(400, "malformed percent escape in the path");
  const std::string& path = *decoded;

  std::string_view rest = path;
  fs::path base = web_root;
  const Mount* mount = nullptr;
  for (const Mount& m : kMounts) {
    if (rest.substr(0, m.prefix.size()) == m.prefix) {
      rest.remove_prefix(m.prefix.size());
      base = web_root / m.folder;
      mount = &m;
      break;
    }
  }

  // Split into segments; refuse anything that could climb out or is hidden.
  std::vector<std::string_view> segments;
  std::size_t start = 0;
  while (start < rest.size()) {
    const std::size_t end = std::min(rest.find('/', start), rest.size());
    const std::string_view seg = rest.substr(start, end - start);
    if (!seg.empty()) segments.push_back(seg);
    start = end + 1;
  }
  for (std::string_view seg : segments) {
    if (seg == "." || seg == "..") return refuse(403, "'.' and '..' are not allowed in a path");
    if (seg.front() == '.') return refuse(403, "hidden files are not served");
    for (char c : seg) {
      if (c == '\\' || static_cast<unsigned char>(c) < 0x20U || c == 0x7f) {
        return refuse(400, "backslashes and control characters are not allowed in a path");
      }
    }
  }
  if (mount == nullptr && !segments.empty() && segments.front() == "node_modules") {
    return refuse(403, "node_modules is served only under /vendor/");
  }

  fs::path relative;
  for (std::string_view seg : segments) relative /= fs::path(std::string(seg));
  if (segments.empty() && mount == nullptr) relative = "index.html";

  std::error_code ec;
  if (mount != nullptr && !fs::is_directory(base, ec)) {
    return refuse(404, std::string(mount->missing) + " (no " + base.string() + ")");
  }
  const fs::path canonical_base = fs::canonical(base, ec);
  if (ec) return refuse(404, "the web root " + base.string() + " does not exist");
  const fs::path file = fs::canonical(base / relative, ec);
  if (ec) return refuse(404, "not found: " + std::string(raw));
  if (!is_within(file, canonical_base)) return refuse(403, "the path leaves the web root");
  if (!fs::is_regular_file(file, ec)) return refuse(404, "not a file: " + std::string(raw));

  StaticTarget t;
  t.status = 200;
  t.file = file;
  return t;
}

std::string_view mime_type(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 16> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/markdown; charset=utf-8"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".wasm", "application/wasm"},
      {".glb", "model/gltf-binary"},
      {".vrm", "model/gltf-binary"},
  }};
  for (const auto& [e, type] : kTypes) {
    if (ext == e) return type;
  }
  return "application/octet-stream";
}

}  // namespace tonus::viewer
