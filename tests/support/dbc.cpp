#include "support/dbc.hpp"

#include <fstream>
#include <regex>
#include <stdexcept>

namespace tonus::test {

std::uint64_t DbcSignal::raw(std::span<const std::uint8_t> data) const {
  std::uint64_t v = 0;
  for (unsigned i = 0; i < length; ++i) {
    const unsigned bit = start_bit + i;
    if (bit / 8 >= data.size()) throw std::out_of_range("signal " + name + " beyond the frame data");
    v |= static_cast<std::uint64_t>((static_cast<unsigned>(data[bit / 8]) >> (bit % 8)) & 1U) << i;
  }
  return v;
}

std::vector<DbcMessage> read_dbc(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  static const std::regex bo(R"(^BO_ (\d+) (\w+): (\d+) (\w+)\s*$)");
  static const std::regex sg(
      R"(^ SG_ (\w+) : (\d+)\|(\d+)@([01])([+-]) \(([-+0-9.eE]+),([-+0-9.eE]+)\) \[[^\]]*\] "[^"]*" [\w,]+\s*$)");
  std::vector<DbcMessage> out;
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_match(line, m, bo)) {
      out.push_back(
          DbcMessage{static_cast<std::uint32_t>(std::stoul(m[1])), m[2], static_cast<unsigned>(std::stoul(m[3])), {}});
    } else if (std::regex_match(line, m, sg)) {
      if (out.empty()) throw std::runtime_error("SG_ before any BO_ in " + path);
      DbcSignal s;
      s.name = m[1];
      s.start_bit = static_cast<unsigned>(std::stoul(m[2]));
      s.length = static_cast<unsigned>(std::stoul(m[3]));
      s.little_endian = m[4] == "1";
      s.is_signed = m[5] == "-";
      s.factor = std::stod(m[6]);
      s.offset = std::stod(m[7]);
      out.back().signals.push_back(s);
    } else if (line.rfind(" SG_", 0) == 0 || line.rfind("BO_ ", 0) == 0) {
      throw std::runtime_error("unparsed DBC line: " + line);
    }
  }
  return out;
}

}  // namespace tonus::test
