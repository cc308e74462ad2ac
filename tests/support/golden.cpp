#include "support/golden.hpp"

#include <cctype>
#include <fstream>
#include <stdexcept>

namespace tonus::test {

namespace {

std::vector<std::string> read_doc() {
  std::ifstream in(std::string(TONUS_SOURCE_DIR) + "/docs/protocol.md");
  if (!in) throw std::runtime_error("cannot open docs/protocol.md");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

std::vector<std::string> golden_block(const std::string& name) {
  const std::vector<std::string> doc = read_doc();
  const std::string marker = "<!-- golden:" + name + " -->";
  std::size_t i = 0;
  while (i < doc.size() && doc[i] != marker) ++i;
  if (i == doc.size()) return {};
  ++i;
  if (i == doc.size() || doc[i].rfind("```", 0) != 0) return {};
  std::vector<std::string> block;
  for (++i; i < doc.size() && doc[i].rfind("```", 0) != 0; ++i) block.push_back(doc[i]);
  return block;
}

std::vector<std::uint8_t> golden_bytes(const std::string& name) {
  std::vector<std::uint8_t> bytes;
  for (const std::string& full : golden_block(name)) {
    const std::string line = full.substr(0, full.find("//"));
    std::string digits;
    for (char c : line) {
      if (std::isxdigit(static_cast<unsigned char>(c))) digits += c;
    }
    if (digits.size() % 2 != 0) throw std::runtime_error("odd hex digit count in golden:" + name);
    for (std::size_t k = 0; k < digits.size(); k += 2) {
      bytes.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(k, 2), nullptr, 16)));
    }
  }
  return bytes;
}

std::string to_hex(std::span<const std::uint8_t> bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i != 0) s += (i % 16 == 0) ? '\n' : ' ';
    s += digits[bytes[i] >> 4U];
    s += digits[bytes[i] & 0xFU];
  }
  return s;
}

}  // namespace tonus::test
