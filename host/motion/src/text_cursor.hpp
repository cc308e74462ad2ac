// A forward cursor over BVH text: blank-separated tokens, line breaks of any
// style (CRLF, LF, lone CR) counted for 1-based line numbers.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace tonus::motion {

// Blanks separate tokens within a line; line breaks are '\n' and '\r'.
[[nodiscard]] constexpr bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
[[nodiscard]] constexpr bool is_line_break(char c) { return c == '\n' || c == '\r'; }

// ASCII case-insensitive equality (keywords and channel names).
[[nodiscard]] bool iequals(std::string_view a, std::string_view b);

// A token as an error message shows it: quoted, shortened, control bytes
// escaped; "end of file" or "end of line" when empty.
[[nodiscard]] std::string describe(std::string_view token, bool at_end_of_file);

class TextCursor {
 public:
  explicit TextCursor(std::string_view text);

  // The next token, crossing line breaks; empty at the end of the text.
  std::string_view next_token();
  // The next token on the current line; empty at the end of the line.
  std::string_view next_token_on_line();
  // The rest of the current line without its line break, blanks trimmed.
  std::string_view rest_of_line();
  // Moves past the current line's break (nothing at the end of the text).
  void skip_line_break();

  // Line of the last token returned (1-based).
  [[nodiscard]] std::size_t token_line() const { return token_line_; }
  // Line the cursor is on now.
  [[nodiscard]] std::size_t line() const { return line_; }
  [[nodiscard]] bool at_end() const { return pos_ >= text_.size(); }
  [[nodiscard]] std::size_t remaining() const { return text_.size() - pos_; }

 private:
  void skip_blanks();
  std::string_view take_token();

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t token_line_ = 1;
};

}  // namespace tonus::motion
