// Forward kinematics over the clip's depth-first order: each joint's parent
// is already posed when the joint is reached, so one pass suffices.
#include "tonus/host/motion/kinematics.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <span>

namespace tonus::motion {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// What FK needs and nothing more: parents earlier than their children, known
// channels, and a row of values for `frame`. Allocation-free.
bool posable(const Clip& clip, std::size_t frame) {
  if (clip.joints.empty() || clip.joints.size() > kMaxJoints) return false;
  std::size_t n = 0;
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const Joint& joint = clip.joints[j];
    if (joint.parent < -1 || joint.parent >= static_cast<int>(j)) return false;
    if (joint.channels.size() > kMaxChannelsPerJoint) return false;
    for (const Channel c : joint.channels) {
      if (static_cast<std::size_t>(c) > static_cast<std::size_t>(Channel::z_rotation)) return false;
    }
    n += joint.channels.size();
  }
  if (n == 0) return frame < clip.frame_count;
  return frame < clip.frame_count && frame < clip.values.size() / n;
}

std::size_t first_column(const Clip& clip, std::size_t joint) {
  std::size_t c = 0;
  for (std::size_t j = 0; j < joint; ++j) c += clip.joints[j].channels.size();
  return c;
}

// The joint's transform from its channel values (see the header's conventions).
void local_transform(const Joint& joint, std::span<const double> values, Eigen::Quaterniond& rotation,
                     Eigen::Vector3d& translation) {
  rotation = Eigen::Quaterniond::Identity();
  translation = joint.offset;
  for (std::size_t c = 0; c < joint.channels.size(); ++c) {
    const Channel channel = joint.channels[c];
    const auto axis = static_cast<Eigen::Index>(channel_axis(channel));
    if (is_rotation(channel)) {
      rotation = rotation * Eigen::AngleAxisd(values[c] * kDegree, Eigen::Vector3d::Unit(axis));
    } else {
      translation[axis] = values[c];
    }
  }
}

// The values of one joint at one frame; the caller has checked posable().
std::span<const double> joint_values(const Clip& clip, std::size_t frame, std::size_t joint) {
  const std::size_t n = clip.channel_count();
  return std::span<const double>(clip.values)
      .subspan(frame * n + first_column(clip, joint), clip.joints[joint].channels.size());
}

// Where a joint's three rotation channels sit in a frame row, in channel
// order (the joint must have a rotation_order).
std::array<std::size_t, 3> rotation_columns(const Clip& clip, std::size_t joint) {
  const Joint& target = clip.joints[joint];
  std::array<std::size_t, 3> columns{};
  std::size_t k = 0;
  for (std::size_t c = 0; c < target.channels.size(); ++c) {
    if (is_rotation(target.channels[c])) columns.at(k++) = first_column(clip, joint) + c;
  }
  return columns;
}

}  // namespace

bool forward_kinematics(const Clip& clip, std::size_t frame, std::vector<JointPose>& out) {
  if (!posable(clip, frame)) {
    out.clear();
    return false;
  }
  out.resize(clip.joints.size());
  const std::size_t n = clip.channel_count();
  std::size_t column = frame * n;
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const Joint& joint = clip.joints[j];
    JointPose& pose = out[j];
    local_transform(joint, std::span<const double>(clip.values).subspan(column, joint.channels.size()),
                    pose.local_rotation, pose.local_translation);
    column += joint.channels.size();
    if (joint.parent < 0) {
      pose.rotation = pose.local_rotation;
      pose.position = pose.local_translation;
    } else {
      const JointPose& parent = out[static_cast<std::size_t>(joint.parent)];
      pose.rotation = parent.rotation * pose.local_rotation;
      pose.position = parent.position + parent.rotation * pose.local_translation;
    }
  }
  return true;
}

std::vector<JointPose> forward_kinematics(const Clip& clip, std::size_t frame) {
  std::vector<JointPose> out;
  forward_kinematics(clip, frame, out);
  return out;
}

std::optional<Eigen::Quaterniond> local_rotation(const Clip& clip, std::size_t frame, std::size_t joint) {
  if (joint >= clip.joints.size() || !posable(clip, frame)) return std::nullopt;
  Eigen::Quaterniond r;
  Eigen::Vector3d t;
  local_transform(clip.joints[joint], joint_values(clip, frame, joint), r, t);
  return r;
}

std::optional<Eigen::Vector3d> local_translation(const Clip& clip, std::size_t frame, std::size_t joint) {
  if (joint >= clip.joints.size() || !posable(clip, frame)) return std::nullopt;
  Eigen::Quaterniond r;
  Eigen::Vector3d t;
  local_transform(clip.joints[joint], joint_values(clip, frame, joint), r, t);
  return t;
}

std::optional<EulerOrder> rotation_order(const Joint& joint) {
  std::array<Axis, 3> found{};
  std::size_t count = 0;
  for (const Channel c : joint.channels) {
    if (!is_rotation(c)) continue;
    if (count == found.size()) return std::nullopt;
    found.at(count++) = static_cast<Axis>(channel_axis(c));
  }
  if (count != found.size()) return std::nullopt;
  return euler_order(found[0], found[1], found[2]);
}

bool set_local_rotation(Clip& clip, std::size_t frame, std::size_t joint, const Eigen::Quaterniond& q) {
  if (joint >= clip.joints.size() || !posable(clip, frame)) return false;
  const double norm = q.norm();
  if (!std::isfinite(norm) || norm == 0.0) return false;
  const Joint& target = clip.joints[joint];
  const std::optional<EulerOrder> order = rotation_order(target);
  if (!order) return false;
  std::array<std::size_t, 3> columns = rotation_columns(clip, joint);
  for (std::size_t& c : columns) c += frame * clip.channel_count();
  const EulerAngles now{clip.values[columns[0]], clip.values[columns[1]], clip.values[columns[2]]};
  const EulerAngles angles = euler_from_quaternion_near(q, *order, now);
  for (std::size_t i = 0; i < 3; ++i) clip.values[columns.at(i)] = angles.at(i);
  return true;
}

bool unwrap_rotation(Clip& clip, std::size_t joint, std::size_t from_frame) {
  if (joint >= clip.joints.size() || clip.frame_count == 0 || !posable(clip, clip.frame_count - 1) ||
      from_frame >= clip.frame_count) {
    return false;
  }
  const std::optional<EulerOrder> order = rotation_order(clip.joints[joint]);
  if (!order) return false;
  const std::size_t n = clip.channel_count();
  const std::array<std::size_t, 3> columns = rotation_columns(clip, joint);
  const auto angles_at = [&](std::size_t f) {
    const std::size_t row = f * n;
    return EulerAngles{clip.values[row + columns[0]], clip.values[row + columns[1]], clip.values[row + columns[2]]};
  };
  const auto distance = [](const EulerAngles& a, const EulerAngles& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  // Rounding moves a re-derived triple by ~1e-12 degrees; a different
  // representation is nearer by far more.
  constexpr double kNearer = 1e-6;
  EulerAngles previous = angles_at(from_frame);
  for (std::size_t f = from_frame + 1; f < clip.frame_count; ++f) {
    const EulerAngles now = angles_at(f);
    const EulerAngles near = euler_from_quaternion_near(quaternion_from_euler(*order, now), *order, previous);
    if (distance(near, previous) < distance(now, previous) - kNearer) {
      for (std::size_t i = 0; i < 3; ++i) clip.values[f * n + columns.at(i)] = near.at(i);
      previous = near;
    } else {
      previous = now;
    }
  }
  return true;
}

bool set_local_translation(Clip& clip, std::size_t frame, std::size_t joint, const Eigen::Vector3d& t) {
  if (joint >= clip.joints.size() || !posable(clip, frame) || !t.allFinite()) return false;
  const Joint& target = clip.joints[joint];
  const std::size_t base = frame * clip.channel_count() + first_column(clip, joint);
  std::array<std::size_t, 3> columns{};
  std::array<bool, 3> found{};
  for (std::size_t c = 0; c < target.channels.size(); ++c) {
    if (is_rotation(target.channels[c])) continue;
    const auto axis = static_cast<std::size_t>(channel_axis(target.channels[c]));
    columns.at(axis) = base + c;
    found.at(axis) = true;
  }
  if (!found[0] || !found[1] || !found[2]) return false;
  for (std::size_t i = 0; i < 3; ++i) clip.values[columns.at(i)] = t[static_cast<Eigen::Index>(i)];
  return true;
}

}  // namespace tonus::motion
