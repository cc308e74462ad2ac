// A whole file as a string (binary-safe); empty if it cannot be read.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace tonus::test {

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace tonus::test
