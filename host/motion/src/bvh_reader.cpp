// BVH reader: a single pass over the text, the hierarchy as tokens (with
// OFFSET and CHANNELS arguments on their own line), then one frame per line.
// No recursion (nesting is bounded by kMaxJoints but kept off the stack) and
// no allocation sized by a count read from the file before the bytes for it
// are known to be there.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

#include "number.hpp"
#include "text_cursor.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace tonus::motion {

namespace {

constexpr std::uint64_t kMaxFrameCount = 1'000'000'000'000ULL;  // keeps frames x channels far from overflow
constexpr double kFrameTimeSlack = 1e-3;                        // relative; 0.0416667 is 1/24 s rounded

std::string shortest(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("?");
}

class BvhReader {
 public:
  BvhReader(std::string_view text, ReadResult& out) : cursor_(text), out_(out) {}

  bool read() { return read_hierarchy() && read_motion(); }

 private:
  // A ROOT, JOINT or End Site whose '}' has not been read yet.
  struct Open {
    std::size_t index = 0;
    bool has_offset = false;
    bool has_channels = false;
    bool has_children = false;
    int end_sites = 0;
  };

  Clip& clip() { return out_.clip; }

  bool fail(std::size_t line, std::string message) {
    out_.error = Diagnostic{line, std::move(message)};
    return false;
  }

  bool expected(const std::string& what, std::string_view found) {
    return fail(cursor_.token_line(), "expected " + what + ", found " + describe(found, cursor_.at_end()));
  }

  std::string what(std::size_t index) const {
    const Joint& j = out_.clip.joints[index];
    return (j.end_site ? "End Site " : "joint ") + describe(j.name, false);  // quoted, control bytes escaped
  }

  bool read_hierarchy();
  bool open_joint(int parent, std::string_view keyword);
  bool open_end_site();
  bool begin_child(std::string_view keyword);
  bool require_header(const Open& open, std::string_view before);
  bool add_entry(Joint joint, bool brace_read, std::string_view after);
  bool read_offset();
  bool read_channels();
  bool read_motion();
  bool read_frames(std::uint64_t declared, std::size_t frames_line);

  TextCursor cursor_;
  ReadResult& out_;
  std::vector<Open> open_;
};

bool BvhReader::read_hierarchy() {
  std::string_view tok = cursor_.next_token();
  if (!iequals(tok, "HIERARCHY")) return expected("HIERARCHY", tok);
  tok = cursor_.next_token();
  if (!iequals(tok, "ROOT")) return expected("ROOT", tok);
  if (!open_joint(-1, "ROOT")) return false;
  while (!open_.empty()) {
    tok = cursor_.next_token();
    if (tok == "}") {
      if (!require_header(open_.back(), "'}'")) return false;
      open_.pop_back();
    } else if (iequals(tok, "OFFSET")) {
      if (!read_offset()) return false;
    } else if (iequals(tok, "CHANNELS")) {
      if (!read_channels()) return false;
    } else if (iequals(tok, "JOINT")) {
      if (!begin_child("JOINT") || !open_joint(static_cast<int>(open_.back().index), "JOINT")) return false;
    } else if (iequals(tok, "End")) {
      if (!begin_child("End Site") || !open_end_site()) return false;
    } else {
      return expected("OFFSET, CHANNELS, JOINT, End Site or '}' in " + what(open_.back().index), tok);
    }
  }
  if (clip().channel_count() == 0) return fail(cursor_.token_line(), "the hierarchy has no channels");
  tok = cursor_.next_token();
  if (iequals(tok, "ROOT")) return fail(cursor_.token_line(), "a second ROOT: a BVH file has exactly one");
  if (!iequals(tok, "MOTION")) return expected("MOTION after the hierarchy", tok);
  return true;
}

// ROOT or JOINT: the name is the rest of the line (names may hold spaces); a
// last blank-separated '{' there is the opening brace.
bool BvhReader::open_joint(int parent, std::string_view keyword) {
  std::string_view name = cursor_.rest_of_line();
  const std::size_t line = cursor_.token_line();
  bool brace = false;
  if (name == "{") {
    name = {};
    brace = true;
  } else if (name.size() >= 2 && name.back() == '{' && is_blank(name[name.size() - 2])) {
    name.remove_suffix(1);
    while (!name.empty() && is_blank(name.back())) name.remove_suffix(1);
    brace = true;
  }
  if (name.empty()) {
    return fail(line, "expected a joint name after " + std::string(keyword) + ", found " +
                          (brace ? std::string("'{'") : describe({}, cursor_.at_end())));
  }
  if (name == "{" || (name.size() >= 2 && name.back() == '{' && is_blank(name[name.size() - 2]))) {
    return fail(line, "expected one '{' after joint " + describe(name, false) + ", found two");
  }
  Joint joint;
  joint.name = std::string(name);
  joint.parent = parent;
  return add_entry(std::move(joint), brace, "joint " + describe(name, false));
}

bool BvhReader::open_end_site() {
  const std::string_view site = cursor_.next_token_on_line();
  if (!iequals(site, "Site")) return expected("'Site' after 'End'", site);
  const std::string_view rest = cursor_.rest_of_line();
  if (!rest.empty() && rest != "{") {
    return fail(cursor_.token_line(), "expected '{' after End Site, found " + describe(rest, false));
  }
  Open& parent = open_.back();
  ++parent.end_sites;
  Joint site_joint;
  site_joint.name = clip().joints[parent.index].name + "_End" +
                    (parent.end_sites > 1 ? std::to_string(parent.end_sites) : std::string());
  site_joint.parent = static_cast<int>(parent.index);
  site_joint.end_site = true;
  return add_entry(std::move(site_joint), rest == "{", "End Site");
}

bool BvhReader::add_entry(Joint joint, bool brace_read, std::string_view after) {
  if (clip().joints.size() >= kMaxJoints) {
    return fail(cursor_.token_line(), "more than " + std::to_string(kMaxJoints) + " joints (End Sites included)");
  }
  if (!brace_read) {
    const std::string_view tok = cursor_.next_token();
    if (tok != "{") return expected("'{' after " + std::string(after), tok);
  }
  open_.push_back(Open{clip().joints.size()});
  clip().joints.push_back(std::move(joint));
  return true;
}

bool BvhReader::begin_child(std::string_view keyword) {
  Open& parent = open_.back();
  if (clip().joints[parent.index].end_site) {
    return fail(cursor_.token_line(), "an End Site cannot hold a " + std::string(keyword) + " (missing '}'?)");
  }
  if (!require_header(parent, std::string(keyword))) return false;
  parent.has_children = true;
  return true;
}

bool BvhReader::require_header(const Open& open, std::string_view before) {
  if (!open.has_offset) {
    return fail(cursor_.token_line(), "expected OFFSET in " + what(open.index) + " before " + std::string(before));
  }
  if (!clip().joints[open.index].end_site && !open.has_channels) {
    return fail(cursor_.token_line(), "expected CHANNELS in " + what(open.index) + " before " + std::string(before));
  }
  return true;
}

bool BvhReader::read_offset() {
  Open& open = open_.back();
  const std::size_t line = cursor_.token_line();
  if (open.has_offset) return fail(line, "a second OFFSET in " + what(open.index));
  if (open.has_children) return fail(line, "OFFSET after the children of " + what(open.index));
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Index count = 0;
  for (std::string_view tok = cursor_.next_token_on_line(); !tok.empty(); tok = cursor_.next_token_on_line()) {
    if (count < 3) {
      double v = 0.0;
      const NumberStatus status = parse_double(tok, v);
      if (status != NumberStatus::ok) {
        return fail(
            line, "expected a finite number in the OFFSET of " + what(open.index) + ", found " + describe(tok, false));
      }
      offset[count] = v;
    }
    ++count;
  }
  if (count != 3) {
    return fail(line, "expected 3 numbers after OFFSET in " + what(open.index) + ", found " + std::to_string(count));
  }
  clip().joints[open.index].offset = offset;
  open.has_offset = true;
  return true;
}

bool BvhReader::read_channels() {
  Open& open = open_.back();
  Joint& joint = clip().joints[open.index];
  const std::size_t line = cursor_.token_line();
  if (open.has_channels) return fail(line, "a second CHANNELS in " + what(open.index));
  if (open.has_children) return fail(line, "CHANNELS after the children of " + what(open.index));
  const std::string_view count_tok = cursor_.next_token_on_line();
  std::uint64_t declared = 0;
  if (!parse_count(count_tok, 1'000'000, declared)) {
    return fail(line, "expected a channel count after CHANNELS, found " + describe(count_tok, cursor_.at_end()));
  }
  if (declared > kMaxChannelsPerJoint) {
    return fail(line, "CHANNELS " + std::to_string(declared) + " in " + what(open.index) + ": at most 6 allowed");
  }
  std::uint64_t listed = 0;
  for (std::string_view tok = cursor_.next_token_on_line(); !tok.empty(); tok = cursor_.next_token_on_line()) {
    if (++listed > declared) continue;  // counted for the message below
    const std::optional<Channel> channel = channel_from_name(tok);
    if (!channel) {
      return fail(line, "unknown channel " + describe(tok, false) +
                            " (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)");
    }
    if (std::find(joint.channels.begin(), joint.channels.end(), *channel) != joint.channels.end()) {
      return fail(line, "channel " + std::string(channel_name(*channel)) + " listed twice in " + what(open.index));
    }
    joint.channels.push_back(*channel);
  }
  if (listed != declared) {
    return fail(line, "CHANNELS " + std::to_string(declared) + " in " + what(open.index) + " lists " +
                          std::to_string(listed) + " channel names");
  }
  if (joint.end_site && declared > 0) return fail(line, "an End Site cannot have channels");
  open.has_channels = true;
  return true;
}

bool BvhReader::read_motion() {
  std::string_view tok = cursor_.next_token();
  if (!iequals(tok, "Frames:")) return expected("'Frames:'", tok);
  const std::size_t frames_line = cursor_.token_line();
  tok = cursor_.next_token();
  std::uint64_t declared = 0;
  if (!parse_count(tok, kMaxFrameCount, declared)) return expected("a frame count after 'Frames:'", tok);
  tok = cursor_.next_token();
  if (!iequals(tok, "Frame")) return expected("'Frame Time:'", tok);
  tok = cursor_.next_token_on_line();
  if (!iequals(tok, "Time:")) return expected("'Frame Time:'", tok);
  tok = cursor_.next_token();
  double frame_time = 0.0;
  if (parse_double(tok, frame_time) != NumberStatus::ok || frame_time <= 0.0) {
    return expected("a positive frame time in seconds", tok);
  }
  const std::size_t time_line = cursor_.token_line();
  tok = cursor_.next_token_on_line();
  if (!tok.empty()) return expected("the end of the line after the frame time", tok);
  cursor_.skip_line_break();
  if (declared == 0) return fail(frames_line, "no motion: 'Frames: 0'");
  if (frame_time < kUsualMinFrameTime_s * (1.0 - kFrameTimeSlack) ||
      frame_time > kUsualMaxFrameTime_s * (1.0 + kFrameTimeSlack)) {
    out_.warnings.push_back({time_line, "frame time " + shortest(frame_time) +
                                            " s is outside the usual 1/240 to 1/24 s; is it in seconds?"});
  }
  clip().frame_time_s = frame_time;
  return read_frames(declared, frames_line);
}

bool BvhReader::read_frames(std::uint64_t declared, std::size_t frames_line) {
  Clip& c = clip();
  const std::size_t n = c.channel_count();
  // Every value takes at least two bytes (a digit and a separator), so the
  // text left bounds what the declared count may reserve.
  c.values.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(declared * n, cursor_.remaining() / 2 + 1)));
  std::uint64_t present = 0;
  while (!cursor_.at_end()) {
    const std::size_t line = cursor_.line();
    std::size_t count = 0;
    for (std::string_view tok = cursor_.next_token_on_line(); !tok.empty(); tok = cursor_.next_token_on_line()) {
      if (++count > n) continue;  // counted for the message below
      double v = 0.0;
      const NumberStatus status = parse_double(tok, v);
      if (status != NumberStatus::ok) {
        return fail(line, "expected a " + std::string(status == NumberStatus::not_finite ? "finite " : "") +
                              "number in frame " + std::to_string(present) + ", found " + describe(tok, false));
      }
      c.values.push_back(v);
    }
    cursor_.skip_line_break();
    if (count == 0) continue;  // blank lines carry no frame
    if (count != n) {
      return fail(line, "frame " + std::to_string(present) + " has " + std::to_string(count) + " values, expected " +
                            std::to_string(n) + " (one per channel)");
    }
    ++present;
  }
  if (present != declared) {
    return fail(frames_line, "'Frames: " + std::to_string(declared) + "' but the file holds " +
                                 std::to_string(present) + " frame lines");
  }
  c.frame_count = static_cast<std::size_t>(declared);
  return true;
}

}  // namespace

ReadResult parse_bvh(std::string_view text) {
  ReadResult result;
  BvhReader reader(text, result);
  if (!reader.read()) result.clip = Clip{};  // nothing half-read leaks out
  return result;
}

ReadResult read_bvh_file(const std::string& path) {
  const auto io_error = [&path](const std::string& what) {
    ReadResult failed;
    failed.error = Diagnostic{0, "'" + path + "': " + what};
    return failed;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return io_error("no such regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return io_error("cannot get its size (" + ec.message() + ")");
  if (size > kMaxFileBytes) return io_error("larger than " + std::to_string(kMaxFileBytes) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error("cannot open");
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.gcount() != static_cast<std::streamsize>(text.size())) return io_error("cannot read");
  return parse_bvh(text);
}

}  // namespace tonus::motion
