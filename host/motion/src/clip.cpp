// Clip layout helpers and the structural checks the writer and FK rely on.
#include "tonus/host/motion/clip.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "text_cursor.hpp"

namespace tonus::motion {

namespace {

constexpr std::array<std::string_view, 6> kChannelNames = {"Xposition", "Yposition", "Zposition",
                                                           "Xrotation", "Yrotation", "Zrotation"};

std::string quoted(const std::string& name) { return "'" + name + "'"; }

// A name the reader gives back unchanged: it takes the rest of the line,
// trimmed, and a last blank-separated "{" as the opening brace.
std::optional<std::string> name_problem(const std::string& name) {
  if (name.empty()) return "a joint has an empty name";
  for (const char c : name) {
    if (c == '\n' || c == '\r') return "joint name " + quoted(name) + " holds a line break";
  }
  if (is_blank(name.front()) || is_blank(name.back())) return "joint name " + quoted(name) + " has surrounding blanks";
  if (name == "{" || (name.size() >= 2 && name.back() == '{' && is_blank(name[name.size() - 2]))) {
    return "joint name " + quoted(name) + " ends in a separate '{'";
  }
  return std::nullopt;
}

}  // namespace

std::string_view channel_name(Channel channel) { return kChannelNames.at(static_cast<std::size_t>(channel)); }

std::optional<Channel> channel_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kChannelNames.size(); ++i) {
    if (iequals(name, kChannelNames[i])) return static_cast<Channel>(i);
  }
  return std::nullopt;
}

std::size_t Clip::channel_count() const {
  std::size_t n = 0;
  for (const Joint& j : joints) n += j.channels.size();
  return n;
}

std::span<const double> Clip::frame(std::size_t f) const {
  const std::size_t n = channel_count();
  if (f >= frame_count || n == 0 || values.size() / n <= f) return {};
  return std::span<const double>(values).subspan(f * n, n);
}

std::span<double> Clip::frame(std::size_t f) {
  const std::size_t n = channel_count();
  if (f >= frame_count || n == 0 || values.size() / n <= f) return {};
  return std::span<double>(values).subspan(f * n, n);
}

std::vector<std::size_t> channel_columns(const Clip& clip) {
  std::vector<std::size_t> columns;
  columns.reserve(clip.joints.size() + 1);
  std::size_t c = 0;
  for (const Joint& j : clip.joints) {
    columns.push_back(c);
    c += j.channels.size();
  }
  columns.push_back(c);
  return columns;
}

std::optional<std::size_t> find_joint(const Clip& clip, std::string_view name) {
  for (std::size_t i = 0; i < clip.joints.size(); ++i) {
    if (clip.joints[i].name == name) return i;
  }
  return std::nullopt;
}

std::optional<std::string> check_hierarchy(const std::vector<Joint>& joints) {
  if (joints.empty()) return "the hierarchy is empty";
  if (joints.size() > kMaxJoints) return "more than " + std::to_string(kMaxJoints) + " joints";
  if (joints.front().parent != -1 || joints.front().end_site) return "the first joint is not a root";
  // Depth-first order: each parent is the previous entry or one of its
  // ancestors, i.e. on the stack of open entries.
  std::vector<std::size_t> open{0};
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const Joint& joint = joints[j];
    if (j > 0) {
      if (joint.parent < 0 || static_cast<std::size_t>(joint.parent) >= j) {
        return "joint " + quoted(joint.name) + " does not have an earlier parent";
      }
      const auto parent = static_cast<std::size_t>(joint.parent);
      if (joints[parent].end_site) return "End Site " + quoted(joints[parent].name) + " has a child";
      while (!open.empty() && open.back() != parent) open.pop_back();
      if (open.empty()) return "joint " + quoted(joint.name) + " is not in depth-first order";
      open.push_back(j);
    }
    if (!joint.offset.allFinite()) return "joint " + quoted(joint.name) + " has a non-finite OFFSET";
    if (joint.end_site && !joint.channels.empty()) return "End Site " + quoted(joint.name) + " has channels";
    if (joint.channels.size() > kMaxChannelsPerJoint) return "joint " + quoted(joint.name) + " has over 6 channels";
    std::array<bool, 6> seen{};
    for (const Channel c : joint.channels) {
      const auto k = static_cast<std::size_t>(c);
      if (k >= seen.size()) return "joint " + quoted(joint.name) + " has an unknown channel";
      if (seen.at(k)) return "joint " + quoted(joint.name) + " repeats a channel";
      seen.at(k) = true;
    }
  }
  return std::nullopt;
}

std::optional<std::string> check_clip(const Clip& clip) {
  if (auto problem = check_hierarchy(clip.joints)) return problem;
  for (const Joint& j : clip.joints) {
    if (j.end_site) continue;  // End Site names are not written
    if (auto problem = name_problem(j.name)) return problem;
  }
  const std::size_t n = clip.channel_count();
  if (n == 0) return "the hierarchy has no channels";
  if (!std::isfinite(clip.frame_time_s) || clip.frame_time_s <= 0.0) return "the frame time is not positive";
  if (clip.frame_count == 0) return "the clip has no frames";
  if (clip.frame_count > std::numeric_limits<std::size_t>::max() / n || clip.values.size() != clip.frame_count * n) {
    return "values hold " + std::to_string(clip.values.size()) +
           " numbers, not frames x channels = " + std::to_string(clip.frame_count) + " x " + std::to_string(n);
  }
  for (std::size_t i = 0; i < clip.values.size(); ++i) {
    if (!std::isfinite(clip.values[i])) {
      return "frame " + std::to_string(i / n) + " column " + std::to_string(i % n) + " is not finite";
    }
  }
  return std::nullopt;
}

}  // namespace tonus::motion
