#include "tonus/protocol/candump.hpp"

namespace tonus::proto::candump {

namespace {

constexpr std::uint32_t kStdMax = 0x7FF;
constexpr std::uint32_t kExtMax = 0x1FFFFFFF;
constexpr std::uint32_t kErrFlag = 0x20000000;  // CAN_ERR_FLAG as candump prints it

constexpr char kHex[] = "0123456789ABCDEF";

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

class Out {
 public:
  explicit Out(std::span<char> buf) : buf_(buf) {}
  void put(char c) {
    if (pos_ < buf_.size()) {
      buf_[pos_] = c;
    } else {
      overflow_ = true;
    }
    ++pos_;
  }
  void str(std::string_view s) {
    for (char c : s) put(c);
  }
  void hex(std::uint64_t v, int digits) {
    for (int i = digits - 1; i >= 0; --i) put(kHex[(v >> (4U * static_cast<unsigned>(i))) & 0xFU]);
  }
  void dec(std::uint64_t v, int min_digits) {
    std::array<char, 20> tmp{};
    int n = 0;
    do {
      tmp[static_cast<std::size_t>(n++)] = static_cast<char>('0' + v % 10);
      v /= 10;
    } while (v != 0);
    for (int i = n; i < min_digits; ++i) put('0');
    while (n > 0) put(tmp[static_cast<std::size_t>(--n)]);
  }
  [[nodiscard]] bool ok() const { return !overflow_; }
  [[nodiscard]] std::size_t size() const { return pos_; }

 private:
  std::span<char> buf_;
  std::size_t pos_ = 0;
  bool overflow_ = false;
};

// Reads an unsigned decimal of 1..max_digits digits.
bool parse_dec(std::string_view& s, std::uint64_t& v, std::size_t max_digits) {
  std::size_t n = 0;
  v = 0;
  while (n < s.size() && s[n] >= '0' && s[n] <= '9') {
    if (n == max_digits) return false;
    v = v * 10 + static_cast<std::uint64_t>(s[n] - '0');
    ++n;
  }
  s.remove_prefix(n);
  return n > 0;
}

}  // namespace

std::string_view Record::iface_name() const {
  std::size_t n = 0;
  while (n < kMaxIfaceName && iface[n] != '\0') ++n;
  return {iface.data(), n};
}

bool set_iface(Record& rec, std::string_view name) {
  if (name.empty() || name.size() > kMaxIfaceName) return false;
  for (char c : name) {
    if (c <= ' ' || c > '~') return false;
  }
  rec.iface.fill('\0');
  for (std::size_t i = 0; i < name.size(); ++i) rec.iface[i] = name[i];
  return true;
}

Error format(const Record& rec, std::span<char> out, std::size_t& written) {
  written = 0;
  const CanFrame& f = rec.frame;
  const std::string_view iface = rec.iface_name();
  if (iface.empty()) return Error::bad_value;
  if (f.dlc > 8) return Error::bad_length;
  const bool extended = (f.flags & (CanFrame::kExtended | CanFrame::kErrorFrame)) != 0;
  if (f.id > (extended ? kExtMax : kStdMax)) return Error::bad_value;

  Out o(out);
  o.put('(');
  o.dec(rec.time_us / 1000000U, 10);
  o.put('.');
  o.dec(rec.time_us % 1000000U, 6);
  o.str(") ");
  o.str(iface);
  o.put(' ');
  if (extended) {
    o.hex(f.id | ((f.flags & CanFrame::kErrorFrame) != 0 ? kErrFlag : 0U), 8);
  } else {
    o.hex(f.id, 3);
  }
  o.put('#');
  if ((f.flags & CanFrame::kRemote) != 0) {
    o.put('R');
    if (f.dlc != 0) o.put(kHex[f.dlc]);
  } else {
    for (std::size_t i = 0; i < f.dlc; ++i) o.hex(f.data[i], 2);
  }
  o.put('\n');
  if (!o.ok()) return Error::buffer_too_small;
  written = o.size();
  return Error::ok;
}

Error parse(std::string_view s, Record& out) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.remove_suffix(1);
  Record rec{};

  // "(seconds.micros)"
  if (s.empty() || s.front() != '(') return Error::bad_value;
  s.remove_prefix(1);
  std::uint64_t sec = 0;
  std::uint64_t usec = 0;
  const std::string_view before_usec = s;
  if (!parse_dec(s, sec, 12) || s.empty() || s.front() != '.') return Error::bad_value;
  s.remove_prefix(1);
  const std::size_t usec_start = before_usec.size() - s.size();
  if (!parse_dec(s, usec, 6) || before_usec.size() - s.size() - usec_start != 6) return Error::bad_value;
  if (s.empty() || s.front() != ')') return Error::bad_value;
  s.remove_prefix(1);
  rec.time_us = sec * 1000000U + usec;

  // " iface "
  if (s.empty() || s.front() != ' ') return Error::bad_value;
  s.remove_prefix(1);
  const std::size_t space = s.find(' ');
  if (space == std::string_view::npos) return Error::truncated;
  if (!set_iface(rec, s.substr(0, space))) return Error::bad_value;
  s.remove_prefix(space + 1);

  // "id#data"
  const std::size_t hash = s.find('#');
  if (hash == std::string_view::npos) return Error::truncated;
  const std::string_view id_text = s.substr(0, hash);
  if (id_text.size() != 3 && id_text.size() != 8) return Error::bad_value;
  std::uint32_t id = 0;
  for (char c : id_text) {
    const int v = hex_value(c);
    if (v < 0) return Error::bad_value;
    id = (id << 4U) | static_cast<std::uint32_t>(v);
  }
  CanFrame& f = rec.frame;
  if (id_text.size() == 8) {
    f.flags |= CanFrame::kExtended;
    if ((id & kErrFlag) != 0) f.flags |= CanFrame::kErrorFrame;
    id &= ~kErrFlag;
    if (id > kExtMax) return Error::bad_value;
  } else if (id > kStdMax) {
    return Error::bad_value;
  }
  f.id = id;
  s.remove_prefix(hash + 1);

  if (!s.empty() && s.front() == '#') return Error::bad_type;  // CAN FD
  if (!s.empty() && s.front() == 'R') {
    f.flags |= CanFrame::kRemote;
    s.remove_prefix(1);
    if (!s.empty()) {
      const int dlc = hex_value(s.front());
      if (dlc < 0 || dlc > 8 || s.size() != 1) return Error::bad_value;
      f.dlc = static_cast<std::uint8_t>(dlc);
    }
  } else {
    if (s.size() % 2 != 0) return Error::bad_value;
    if (s.size() > 16) return Error::bad_length;
    for (std::size_t i = 0; i < s.size(); i += 2) {
      const int hi = hex_value(s[i]);
      const int lo = hex_value(s[i + 1]);
      if (hi < 0 || lo < 0) return Error::bad_value;
      f.data[i / 2] = static_cast<std::uint8_t>((hi << 4) | lo);
    }
    f.dlc = static_cast<std::uint8_t>(s.size() / 2);
  }
  out = rec;
  return Error::ok;
}

}  // namespace tonus::proto::candump
