// A motion clip as a BVH file holds it: the joint hierarchy in file order and
// one row of channel values per frame, in the file's own frame and units.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tonus::motion {

// Limits that keep a hostile file from costing unbounded memory or time.
inline constexpr std::size_t kMaxJoints = 1024;  // hierarchy entries, End Sites included
inline constexpr std::size_t kMaxChannelsPerJoint = 6;

// The six BVH channels. Positions are in file units, rotations in degrees.
enum class Channel : std::uint8_t { x_position, y_position, z_position, x_rotation, y_rotation, z_rotation };

// "Xposition" ... "Zrotation", as the BVH format spells them.
[[nodiscard]] std::string_view channel_name(Channel channel);
// The channel of a BVH name, matched without regard to case ("XROTATION" and
// "Xrotation" both name x_rotation); nothing for any other word.
[[nodiscard]] std::optional<Channel> channel_from_name(std::string_view name);
[[nodiscard]] constexpr bool is_rotation(Channel c) { return c >= Channel::x_rotation; }
// 0, 1 or 2 for the x, y or z axis of a position or rotation channel.
[[nodiscard]] constexpr int channel_axis(Channel c) { return static_cast<int>(c) % 3; }

// One hierarchy entry: a ROOT, a JOINT or an End Site.
struct Joint {
  // The file's name. An End Site has none in the file and is named
  // "<parent>_End" ("<parent>_End2", ... if a joint has several).
  std::string name;
  int parent = -1;  // index in Clip::joints, lower than this entry's own; -1 only for the root
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // OFFSET: rest translation from the parent, file units
  std::vector<Channel> channels;  // in file order: the order of the frame values and of the rotation product
  bool end_site = false;          // an End Site: no channels, no children
};

// A whole clip. Joints are in file order, which is depth-first with every
// parent before its children; frame f's values are
// values[f * channel_count() .. (f + 1) * channel_count()), joint by joint in
// that order, each joint's channels in its own order.
struct Clip {
  std::vector<Joint> joints;
  double frame_time_s = 0.0;
  std::size_t frame_count = 0;
  std::vector<double> values;  // frame_count x channel_count(), row-major

  // Sum of every joint's channel count (the columns of a frame row).
  [[nodiscard]] std::size_t channel_count() const;
  // One frame's row; empty if f is not a frame of values.
  [[nodiscard]] std::span<const double> frame(std::size_t f) const;
  [[nodiscard]] std::span<double> frame(std::size_t f);
};

// Column of each joint's first channel in a frame row, plus one last entry
// holding channel_count(): joint j's channels are columns [c[j], c[j + 1]).
[[nodiscard]] std::vector<std::size_t> channel_columns(const Clip& clip);

// Index of the first entry (End Sites included) named `name`, if any.
[[nodiscard]] std::optional<std::size_t> find_joint(const Clip& clip, std::string_view name);

// The first structural problem of a hierarchy, or nothing: one root first,
// parents before children in depth-first order, End Sites childless and
// without channels, at most six channels per joint with none repeated,
// finite offsets, at most kMaxJoints entries.
[[nodiscard]] std::optional<std::string> check_hierarchy(const std::vector<Joint>& joints);

// The first problem that keeps `clip` from being written and read back as
// the same clip, or nothing: check_hierarchy, names that fit on a BVH line
// (non-empty, no line break, no surrounding blanks), at least one channel,
// a finite positive frame time, at least one frame, values sized
// frame_count x channel_count() and all finite.
[[nodiscard]] std::optional<std::string> check_clip(const Clip& clip);

}  // namespace tonus::motion
