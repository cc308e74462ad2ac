// BVH (Biovision hierarchy) files: reader and writer.
//
// Reader: accepts what real exporters write: spaces or tabs, CRLF, LF, CR or
// mixed line endings, a UTF-8 byte order mark, keywords and channel names in
// any letter case ("End Site", "End site"), "Frames:" and "Frame Time:"
// followed by spaces or a tab, numbers such as ".0083333", "-0.00000",
// "+1", "7.7e-06", joint names containing spaces (the rest of the line), and
// blank lines among the frames, CHANNELS before OFFSET. OFFSET and CHANNELS
// must keep their arguments on their own line; each frame is one line.
// It refuses, with the 1-based line and what was expected and found: a
// truncated file, missing braces, a second ROOT, unknown or repeated
// channels, a CHANNELS count different from the names listed, more than 6
// channels on a joint or kMaxJoints entries, a frame line with more or fewer
// values than channels, a value that is not a finite number, a Frames: count
// different from the frame lines present, zero frames, and a frame time that
// is not a finite positive number. Memory is bounded by the text's size.
//
// Writer: the standard layout (tab indentation, LF line endings).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tonus/host/motion/clip.hpp"

namespace tonus::motion {

// Files larger than this are refused before they are read (about 50 hours
// of a 31-joint clip at 120 Hz).
inline constexpr std::size_t kMaxFileBytes = std::size_t{1} << 30U;

// Frame times outside this range are accepted with a warning: they are
// probably not seconds per frame (1/240 s to 1/24 s, with 0.1 % slack for
// rounded values such as 0.0416667).
inline constexpr double kUsualMinFrameTime_s = 1.0 / 240.0;
inline constexpr double kUsualMaxFrameTime_s = 1.0 / 24.0;

struct Diagnostic {
  std::size_t line = 0;  // 1-based line of the text; 0 when not tied to a line (I/O errors)
  std::string message;
};

// What reading gives: the clip, or the first error; warnings either way.
struct ReadResult {
  Clip clip;                        // meaningful only when ok()
  std::optional<Diagnostic> error;  // why the text was refused
  std::vector<Diagnostic> warnings;

  [[nodiscard]] bool ok() const { return !error.has_value(); }
};

// Parses a whole BVH text. Never throws (except std::bad_alloc when memory
// runs out), never reads outside `text`.
[[nodiscard]] ReadResult parse_bvh(std::string_view text);

// Reads and parses a file; I/O errors (missing, unreadable, larger than
// kMaxFileBytes) come back as an error with line 0.
[[nodiscard]] ReadResult read_bvh_file(const std::string& path);

// The clip as BVH text: tab indentation, LF line endings, OFFSETs and the
// frame time in the shortest form that reads back to the same double, frame
// values in fixed notation with `decimals` digits after the point (clamped to
// 0..17). Reading the text back gives the same hierarchy and frame time and
// every value rounded to `decimals` digits; writing that again gives the same
// text. An invalid clip (check_clip fails) gives an empty string.
[[nodiscard]] std::string write_bvh(const Clip& clip, int decimals = 6);

}  // namespace tonus::motion
