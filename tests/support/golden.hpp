// Golden test vectors kept in docs/protocol.md, so the document and the code
// cannot drift apart. A vector is a fenced block right after a marker line
// "<!-- golden:NAME -->"; hex blocks hold bytes, candump blocks hold lines.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tonus::test {

// Lines of the fenced block following the marker; empty if the marker is absent.
std::vector<std::string> golden_block(const std::string& name);

// The block's hex bytes (whitespace and "//" comments ignored).
std::vector<std::uint8_t> golden_bytes(const std::string& name);

std::string to_hex(std::span<const std::uint8_t> bytes);

}  // namespace tonus::test
