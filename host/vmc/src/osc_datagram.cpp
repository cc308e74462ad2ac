#include "osc_datagram.hpp"

#include <cstdint>
#include <cstring>

namespace tonus::vmc::detail {

namespace {

constexpr char kBundleTag[] = "#bundle";   // with its NUL: 8 bytes
constexpr std::size_t kBundleHeader = 16;  // tag + 8-byte time tag

std::uint32_t read_be32(const unsigned char* p) {
  return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
         (static_cast<std::uint32_t>(p[2]) << 8) | static_cast<std::uint32_t>(p[3]);
}

bool is_bundle(const unsigned char* data, std::size_t size) {
  return size >= sizeof(kBundleTag) && std::memcmp(data, kBundleTag, sizeof(kBundleTag)) == 0;
}

void decode_message(unsigned char* data, std::size_t size, OscSink& sink) {
  int result = 0;
  lo_message msg = lo_message_deserialise(data, size, &result);
  if (msg == nullptr) {
    sink.malformed();
    return;
  }
  // Deserialising checked the path: a NUL-terminated string at the start.
  sink.message(reinterpret_cast<const char*>(data), msg);
  lo_message_free(msg);
}

void decode(unsigned char* data, std::size_t size, OscSink& sink, int depth) {
  if (!is_bundle(data, size)) {
    decode_message(data, size, sink);
    return;
  }
  if (depth >= kMaxBundleDepth || size < kBundleHeader) {
    sink.malformed();
    return;
  }
  sink.bundle_begin();
  std::size_t pos = kBundleHeader;
  while (pos < size) {
    if (size - pos < 4) {
      sink.malformed();
      break;
    }
    const std::uint32_t length = read_be32(data + pos);
    pos += 4;
    // An element is a whole number of 4-byte words inside the datagram.
    if (length == 0 || length % 4 != 0 || length > size - pos) {
      sink.malformed();
      break;
    }
    decode(data + pos, length, sink, depth + 1);
    pos += length;
  }
  sink.bundle_end();
}

}  // namespace

void decode_datagram(unsigned char* data, std::size_t size, OscSink& sink) {
  if (size == 0 || size % 4 != 0) {
    sink.malformed();
    return;
  }
  decode(data, size, sink, 0);
}

}  // namespace tonus::vmc::detail
