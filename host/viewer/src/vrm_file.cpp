#include "tonus/host/viewer/vrm_file.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace tonus::viewer {

namespace {

// GLB layout (glTF 2.0, "Binary glTF Layout"): a 12-byte header (magic,
// version, length), then chunks of (length, type, data); the first is JSON.
constexpr std::uint32_t kGlbMagic = 0x46546C67U;      // "glTF"
constexpr std::uint32_t kGlbJsonChunk = 0x4E4F534AU;  // "JSON"
constexpr std::size_t kHeaderBytes = 12;
constexpr std::size_t kChunkHeaderBytes = 8;

std::uint32_t le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8U) |
         (static_cast<std::uint32_t>(p[2]) << 16U) | (static_cast<std::uint32_t>(p[3]) << 24U);
}

VrmFileInfo fail(std::string why) {
  VrmFileInfo info;
  info.error = std::move(why);
  return info;
}

std::string mib(std::uintmax_t bytes) { return std::to_string((bytes + (std::uintmax_t{1} << 19U)) >> 20U) + " MiB"; }

}  // namespace

VrmFileInfo check_vrm_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  if (path.empty()) return fail("no file named");
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return fail("no such file");
  if (fs::is_directory(status)) return fail("a directory, not a .vrm file");
  if (!fs::is_regular_file(status)) return fail("not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return fail("cannot read its size (" + ec.message() + ")");
  if (size > max_bytes) {
    return fail("too large: " + std::to_string(size) + " bytes, more than the " + mib(max_bytes) +
                " the viewer serves");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(std::string("cannot open it (") + std::strerror(errno) + ")");
  std::array<unsigned char, kHeaderBytes + kChunkHeaderBytes> head{};
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got < kHeaderBytes || le32(head.data()) != kGlbMagic) {
    return fail("not a glTF binary (a .vrm file starts with \"glTF\"); export it again as .vrm");
  }
  const std::uint32_t version = le32(head.data() + 4);
  if (version != 2) return fail("glTF binary version " + std::to_string(version) + ", only version 2 is read");
  const std::uint32_t length = le32(head.data() + 8);
  if (length != size) {
    return fail("its header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size) +
                " (truncated or damaged?)");
  }
  if (got < head.size()) return fail("too short for a glTF binary (no JSON chunk)");
  const std::uint32_t json_bytes = le32(head.data() + kHeaderBytes);
  const std::uint32_t chunk_type = le32(head.data() + kHeaderBytes + 4);
  if (chunk_type != kGlbJsonChunk || json_bytes == 0 || json_bytes > size - kHeaderBytes - kChunkHeaderBytes) {
    return fail("damaged glTF binary: its first chunk is not a JSON chunk that fits the file");
  }
  VrmFileInfo info;
  info.bytes = size;
  return info;
}

}  // namespace tonus::viewer
