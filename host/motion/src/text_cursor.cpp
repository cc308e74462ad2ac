#include "text_cursor.hpp"

#include <algorithm>
#include <cstdio>

namespace tonus::motion {

namespace {

constexpr std::size_t kShownTokenChars = 40;

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

}  // namespace

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return lower(x) == lower(y); });
}

std::string describe(std::string_view token, bool at_end_of_file) {
  if (token.empty()) return at_end_of_file ? "end of file" : "end of line";
  std::string out = "'";
  for (const char c : token.substr(0, kShownTokenChars)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned>(u));
      out += hex;
    }
  }
  if (token.size() > kShownTokenChars) out += "...";
  return out + "'";
}

TextCursor::TextCursor(std::string_view text) : text_(text) {
  // A UTF-8 byte order mark some Windows tools put first.
  if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;
}

void TextCursor::skip_blanks() {
  while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
}

void TextCursor::skip_line_break() {
  if (pos_ >= text_.size()) return;
  if (text_[pos_] == '\r') {
    ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
    ++line_;
  } else if (text_[pos_] == '\n') {
    ++pos_;
    ++line_;
  }
}

std::string_view TextCursor::take_token() {
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_blank(text_[pos_]) && !is_line_break(text_[pos_])) ++pos_;
  token_line_ = line_;
  return text_.substr(start, pos_ - start);
}

std::string_view TextCursor::next_token() {
  for (;;) {
    skip_blanks();
    if (pos_ >= text_.size()) {
      token_line_ = line_;
      return {};
    }
    if (!is_line_break(text_[pos_])) return take_token();
    skip_line_break();
  }
}

std::string_view TextCursor::next_token_on_line() {
  skip_blanks();
  if (pos_ >= text_.size() || is_line_break(text_[pos_])) {
    token_line_ = line_;
    return {};
  }
  return take_token();
}

std::string_view TextCursor::rest_of_line() {
  skip_blanks();
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_line_break(text_[pos_])) ++pos_;
  std::size_t end = pos_;
  while (end > start && is_blank(text_[end - 1])) --end;
  token_line_ = line_;
  return text_.substr(start, end - start);
}

}  // namespace tonus::motion
