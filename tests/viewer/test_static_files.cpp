// Which file a request target names under the web root, and its MIME type,
// without sockets: the layout (docs/viewer.md), traversal refused in every
// spelling, the three.js hint when node_modules is missing.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tonus/host/viewer/static_files.hpp"

namespace tv = tonus::viewer;
namespace fs = std::filesystem;

namespace {

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

// A web root in a fresh temporary folder, with a secret file beside it.
struct TempRoot {
  fs::path dir;
  fs::path root;
  explicit TempRoot(bool with_three = true) {
    std::string pattern = (fs::temp_directory_path() / "tonus-viewer-XXXXXX").string();
    REQUIRE(mkdtemp(pattern.data()) != nullptr);
    dir = pattern;
    root = dir / "web";
    write(root / "index.html", "<!doctype html>");
    write(root / "js" / "main.js", "export {};");
    write(root / "css" / "viewer.css", "body {}");
    write(root / ".hidden", "secret");
    write(dir / "secret.txt", "outside the web root");
    if (with_three) {
      write(root / "node_modules" / "three" / "build" / "three.module.js", "export const REVISION = '0';");
      write(root / "node_modules" / "three" / "examples" / "jsm" / "controls" / "OrbitControls.js", "export {};");
      write(root / "node_modules" / "puppeteer-core" / "package.json", "{}");
      write(root / "node_modules" / "@pixiv" / "three-vrm" / "lib" / "three-vrm.module.js", "export {};");
    }
    fs::create_symlink(dir / "secret.txt", root / "escape.txt");
  }
  ~TempRoot() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  TempRoot(const TempRoot&) = delete;
  TempRoot& operator=(const TempRoot&) = delete;
  TempRoot(TempRoot&&) = delete;
  TempRoot& operator=(TempRoot&&) = delete;

  [[nodiscard]] tv::StaticTarget get(const std::string& target) const { return tv::resolve_static(root, target); }
};

}  // namespace

TEST_CASE("viewer static files: the page, its modules and three.js under /vendor/") {
  const TempRoot t;
  const fs::path root = fs::canonical(t.root);
  CHECK(t.get("/").file == root / "index.html");
  CHECK(t.get("/").status == 200);
  CHECK(t.get("/index.html").file == root / "index.html");
  CHECK(t.get("/js/main.js").file == root / "js" / "main.js");
  CHECK(t.get("/js/main.js?v=3#top").file == root / "js" / "main.js");
  CHECK(t.get("/css//viewer.css").file == root / "css" / "viewer.css");
  CHECK(t.get("/vendor/three/three.module.js").file == root / "node_modules/three/build/three.module.js");
  CHECK(t.get("/vendor/three/addons/controls/OrbitControls.js").file ==
        root / "node_modules/three/examples/jsm/controls/OrbitControls.js");
  CHECK(t.get("/%6As/main.js").file == root / "js" / "main.js");  // %6A = 'j'
  CHECK(t.get("/vendor/three-vrm/three-vrm.module.js").file ==
        root / "node_modules/@pixiv/three-vrm/lib/three-vrm.module.js");
  CHECK(t.get("/vendor/three-vrm/../../three/build/three.module.js").status == 403);
  CHECK(t.get("/node_modules/@pixiv/three-vrm/lib/three-vrm.module.js").status == 403);
}

TEST_CASE("viewer static files: missing files are 404") {
  const TempRoot t;
  CHECK(t.get("/nope.js").status == 404);
  CHECK(t.get("/js").status == 404);  // a folder
  CHECK(t.get("/vendor/three/nope.js").status == 404);
  CHECK(tv::resolve_static(t.dir / "no-such-root", "/").status == 404);
}

TEST_CASE("viewer static files: traversal is refused in every spelling") {
  const TempRoot t;
  for (const char* target :
       {"/../secret.txt", "/js/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E/secret.txt", "/.%2e/secret.txt",
        "/%2e%2e%2fsecret.txt", "/js/%2e%2e/%2e%2e/secret.txt", "/vendor/three/../../../../secret.txt",
        "/vendor/three/addons/../../../../../secret.txt", "/./index.html", "/..", "/%2e%2e"}) {
    CAPTURE(target);
    const tv::StaticTarget r = t.get(target);
    CHECK(r.status == 403);
    CHECK(r.file.empty());
  }
  // Absolute paths stay under the root (a leading "//" is not the file system's root).
  CHECK(t.get("//etc/passwd").status == 404);
  CHECK(t.get("/%2fetc/passwd").status == 404);
  // A symlink out of the root is refused by its real path.
  CHECK(t.get("/escape.txt").status == 403);
  // Hidden files and node_modules itself are not served.
  CHECK(t.get("/.hidden").status == 403);
  CHECK(t.get("/%2ehidden").status == 403);
  CHECK(t.get("/node_modules/puppeteer-core/package.json").status == 403);
  CHECK(t.get("/vendor/three/../../puppeteer-core/package.json").status == 403);
}

TEST_CASE("viewer static files: malformed targets are 400") {
  const TempRoot t;
  CHECK(t.get("").status == 400);
  CHECK(t.get("index.html").status == 400);
  CHECK(t.get("/%").status == 400);
  CHECK(t.get("/%4").status == 400);
  CHECK(t.get("/%zz").status == 400);
  CHECK(t.get("/js%00/main.js").status == 400);
  CHECK(t.get("/js\\main.js").status == 400);
  CHECK(t.get("/js/%5c..%5c..%5csecret.txt").status == 400);
}

TEST_CASE("viewer static files: without node_modules, three.js's and three-vrm's paths say how to install them") {
  const TempRoot t(false);
  const tv::StaticTarget r = t.get("/vendor/three/three.module.js");
  CHECK(r.status == 404);
  CHECK(r.error.find(std::string(tv::kThreeMissing)) != std::string::npos);
  CHECK(t.get("/vendor/three/addons/controls/OrbitControls.js").error.find("scripts/install-deps.sh") !=
        std::string::npos);
  CHECK(t.get("/").status == 200);  // the page itself still loads
  const tv::StaticTarget vrm = t.get("/vendor/three-vrm/three-vrm.module.js");
  CHECK(vrm.status == 404);
  CHECK(vrm.error.find(std::string(tv::kThreeVrmMissing)) != std::string::npos);
}

TEST_CASE("viewer static files: MIME types") {
  CHECK(tv::mime_type("index.html") == "text/html; charset=utf-8");
  CHECK(tv::mime_type("a/main.js") == "text/javascript; charset=utf-8");
  CHECK(tv::mime_type("x.MJS") == "text/javascript; charset=utf-8");
  CHECK(tv::mime_type("viewer.css") == "text/css; charset=utf-8");
  CHECK(tv::mime_type("package.json") == "application/json");
  CHECK(tv::mime_type("shot.png") == "image/png");
  CHECK(tv::mime_type("icon.svg") == "image/svg+xml");
  CHECK(tv::mime_type("avatar.vrm") == "model/gltf-binary");
  CHECK(tv::mime_type("blob") == "application/octet-stream");
  CHECK(tv::mime_type("x.exe") == "application/octet-stream");
}

TEST_CASE("viewer static files: percent decoding") {
  CHECK(tv::percent_decode("a%20b") == "a b");
  CHECK(tv::percent_decode("%2e%2E") == "..");
  CHECK(tv::percent_decode("a+b") == "a+b");
  CHECK_FALSE(tv::percent_decode("%"));
  CHECK_FALSE(tv::percent_decode("%2"));
  CHECK_FALSE(tv::percent_decode("%g0"));
}

TEST_CASE("viewer static files: the default web root is the source tree's page") {
  const fs::path root = tv::default_web_root();
  CHECK(root.filename() == "web");
  CHECK(fs::is_regular_file(root / "index.html"));
}
