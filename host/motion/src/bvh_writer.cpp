// BVH writer: the standard layout, numbers through std::to_chars (locale-free,
// exact: shortest round-trip form for the hierarchy, fixed for frame values).
#include <algorithm>
#include <array>
#include <charconv>
#include <string>
#include <system_error>

#include "tonus/host/motion/bvh.hpp"

namespace tonus::motion {

namespace {

// Fixed notation of the largest double needs 309 integer digits.
constexpr std::size_t kNumberBuffer = 400;
constexpr int kMaxDecimals = 17;

void append_shortest(std::string& out, double v) {
  std::array<char, kNumberBuffer> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  if (ec == std::errc{}) out.append(buf.data(), end);
}

void append_fixed(std::string& out, double v, int decimals) {
  std::array<char, kNumberBuffer> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed, decimals);
  if (ec == std::errc{}) out.append(buf.data(), end);
}

void indent(std::string& out, std::size_t depth) { out.append(depth, '\t'); }

void write_hierarchy(std::string& out, const Clip& clip) {
  out += "HIERARCHY\n";
  std::vector<std::size_t> open;  // entries whose '}' is still due; the clip is in depth-first order
  auto close_until = [&out, &open](int parent) {
    while (!open.empty() && static_cast<int>(open.back()) != parent) {
      open.pop_back();
      indent(out, open.size());
      out += "}\n";
    }
  };
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const Joint& joint = clip.joints[j];
    close_until(joint.parent);
    const std::size_t depth = open.size();
    indent(out, depth);
    if (joint.end_site) {
      out += "End Site\n";
    } else {
      out += joint.parent < 0 ? "ROOT " : "JOINT ";
      out += joint.name;
      out += '\n';
    }
    indent(out, depth);
    out += "{\n";
    indent(out, depth + 1);
    out += "OFFSET";
    for (Eigen::Index k = 0; k < 3; ++k) {
      out += ' ';
      append_shortest(out, joint.offset[k]);
    }
    out += '\n';
    if (!joint.end_site) {
      indent(out, depth + 1);
      out += "CHANNELS ";
      out += std::to_string(joint.channels.size());
      for (const Channel c : joint.channels) {
        out += ' ';
        out += channel_name(c);
      }
      out += '\n';
    }
    open.push_back(j);
  }
  close_until(-1);
}

}  // namespace

std::string write_bvh(const Clip& clip, int decimals) {
  if (check_clip(clip)) return {};
  decimals = std::clamp(decimals, 0, kMaxDecimals);
  std::string out;
  // About 10 bytes per value at 6 decimals; a guess, not a bound.
  out.reserve(clip.values.size() * static_cast<std::size_t>(4 + decimals) + 64 * clip.joints.size() + 64);
  write_hierarchy(out, clip);
  out += "MOTION\nFrames: ";
  out += std::to_string(clip.frame_count);
  out += "\nFrame Time: ";
  append_shortest(out, clip.frame_time_s);
  out += '\n';
  const std::size_t n = clip.channel_count();
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    for (std::size_t c = 0; c < n; ++c) {
      if (c > 0) out += ' ';
      append_fixed(out, clip.values[f * n + c], decimals);
    }
    out += '\n';
  }
  return out;
}

}  // namespace tonus::motion
