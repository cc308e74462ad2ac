#include "tonus/host/vmc/receiver.hpp"

#include <arpa/inet.h>
#include <lo/lo.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>

#include "osc_datagram.hpp"
#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/host/vmc/unity_frame.hpp"
#include "tracker_roles.hpp"
#include "unity_bones.hpp"

namespace tonus::vmc {

using reference::Tracker;
using sim::Bone;

namespace {

constexpr std::size_t kN = sim::kBoneCount;

// BodyRetarget::create's required bones (plus the neck or the head).
constexpr std::array<Bone, 13> kRequired{
    Bone::Hips,          Bone::LeftUpperLeg,  Bone::LeftLowerLeg, Bone::LeftFoot,     Bone::RightUpperLeg,
    Bone::RightLowerLeg, Bone::RightFoot,     Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand,
    Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand};

// The ankle's height over the floor as a share of the hip-to-ankle length
// (de Leva / Winter proportions: about 0.039 of the stature over 0.49):
// a VMC sender never says where its floor is under the rest pose.
constexpr double kAnkleHeightShare = 0.08;

std::int64_t steady_now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// liblo's argv points into 4-byte aligned OSC data, but lo_arg (a union
// holding doubles) asks for 8: read the bytes, never through the union.
template <class T>
T arg_as(const lo_arg* a) {
  T v{};
  std::memcpy(&v, static_cast<const void*>(a), sizeof(v));
  return v;
}
const char* arg_string(const lo_arg* a) { return reinterpret_cast<const char*>(a); }

bool read_number(char type, const lo_arg* a, double& out) {
  if (type == 'f') {
    out = static_cast<double>(arg_as<float>(a));
  } else if (type == 'd') {
    out = arg_as<double>(a);
  } else {
    return false;
  }
  return std::isfinite(out);
}

// (string name)(7 numbers: px py pz qx qy qz qw), extra arguments accepted
// (V2.1's scale and offset). False: malformed.
bool read_transform(lo_message m, double unit_tolerance, std::string_view& name, UnityTransform& t) {
  const char* types = lo_message_get_types(m);
  lo_arg** argv = lo_message_get_argv(m);
  if (types == nullptr || lo_message_get_argc(m) < 8) return false;
  if (types[0] != 's' && types[0] != 'S') return false;
  name = std::string_view(arg_string(argv[0]));
  std::array<double, 7> v{};
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!read_number(types[k + 1], argv[k + 1], v[k])) return false;
  }
  const sim::Quat q(v[6], v[3], v[4], v[5]);
  const double n = q.norm();
  if (!(std::abs(n - 1.0) <= unit_tolerance)) return false;
  t.pos_m = sim::Vec3(v[0], v[1], v[2]);
  t.rot = sim::Quat(q.coeffs() / n);
  return true;
}

reference::TrackerPose to_internal(const UnityTransform& u) { return {from_unity(u.pos_m), from_unity(u.rot), true}; }

}  // namespace

struct VmcReceiver::State final : detail::OscSink {
  State(const ReceiverOptions& o, const Handler& h) : opt(o), handler(h), roles(o.serial_map) { frame.mode = o.mode; }

  const ReceiverOptions& opt;
  const Handler& handler;
  ReceiverCounters counters;
  SenderStatus status;
  alignas(8) std::array<unsigned char, 65536> buffer{};  // any UDP datagram
  std::int64_t arrival_us = 0;
  int depth = 0;
  bool frame_has_pose = false;
  ReceivedFrame frame;

  // Performer: the latest of everything (Unity frame), what this frame brought.
  UnityTransform root;
  bool root_now = false;
  std::array<UnityTransform, kN> local{};
  std::array<bool, kN> seen{};
  std::array<bool, kN> now{};
  UnityTransform upper_chest;
  bool upper_chest_seen = false;
  bool upper_chest_now = false;
  int skeleton_count = 0;
  std::optional<reference::SourceSkeleton> skeleton;

  // Tracker: the latest pose per tracker (internal frame), and this frame's.
  detail::TrackerRoles roles;
  std::array<reference::TrackerPose, reference::kTrackerCount> tracker{};
  std::array<bool, reference::kTrackerCount> tracker_now{};

  void datagram(std::size_t size) {
    ++counters.datagrams;
    status.last_arrival_us = arrival_us;
    depth = 0;
    detail::decode_datagram(buffer.data(), size, *this);
  }

  void bundle_begin() override {
    ++counters.bundles;
    ++depth;
  }
  void bundle_end() override {
    if (--depth == 0) complete();
  }
  void malformed() override { ++counters.malformed; }

  void message(const char* path, lo_message msg) override {
    ++counters.messages;
    const std::string_view p(path);
    const bool performer = opt.mode == ReceiverMode::performer;
    if (p == "/VMC/Ext/OK") {
      ok_message(msg);
    } else if (p == "/VMC/Ext/T") {
      time_message(msg);
    } else if (performer && p == "/VMC/Ext/Root/Pos") {
      root_message(msg);
    } else if (performer && p == "/VMC/Ext/Bone/Pos") {
      bone_message(msg);
    } else if (!performer && p == "/VMC/Ext/Hmd/Pos") {
      tracker_message(msg, detail::TrackerSource::hmd);
    } else if (!performer && p == "/VMC/Ext/Con/Pos") {
      tracker_message(msg, detail::TrackerSource::controller);
    } else if (!performer && p == "/VMC/Ext/Tra/Pos") {
      tracker_message(msg, detail::TrackerSource::tracker);
    } else {
      ++counters.ignored;
    }
    if (depth == 0) complete();
  }

  void ok_message(lo_message msg) {
    const char* types = lo_message_get_types(msg);
    lo_arg** argv = lo_message_get_argv(msg);
    const int argc = lo_message_get_argc(msg);
    if (types == nullptr || argc < 1 || types[0] != 'i') {
      ++counters.malformed;
      return;
    }
    const auto arg = [&](int k) { return k < argc && types[k] == 'i' ? arg_as<std::int32_t>(argv[k]) : -1; };
    status.ok_seen = true;
    status.loaded = arg_as<std::int32_t>(argv[0]);
    status.calibration_state = arg(1);
    status.calibration_mode = arg(2);
    status.tracking_status = arg(3);
  }

  void time_message(lo_message msg) {
    const char* types = lo_message_get_types(msg);
    double t = 0.0;
    if (types == nullptr || lo_message_get_argc(msg) < 1 || !read_number(types[0], lo_message_get_argv(msg)[0], t)) {
      ++counters.malformed;
      return;
    }
    status.time_s = t;
  }

  void root_message(lo_message msg) {
    std::string_view name;
    if (!read_transform(msg, opt.unit_tolerance, name, root)) {
      ++counters.malformed;
      return;
    }
    root_now = true;
    frame_has_pose = true;
  }

  void bone_message(lo_message msg) {
    std::string_view name;
    UnityTransform t;
    if (!read_transform(msg, opt.unit_tolerance, name, t)) {
      ++counters.malformed;
      return;
    }
    const detail::UnityBone b = detail::classify_unity_bone(name);
    switch (b.kind) {
      case detail::UnityBoneKind::tonus: {
        const std::size_t i = sim::index(b.bone);
        local[i] = t;
        seen[i] = true;
        now[i] = true;
        frame_has_pose = true;
        break;
      }
      case detail::UnityBoneKind::upper_chest:
        upper_chest = t;
        upper_chest_seen = true;
        upper_chest_now = true;
        frame_has_pose = true;
        break;
      case detail::UnityBoneKind::other: break;  // fingers, eyes, jaw: valid, not used
      case detail::UnityBoneKind::unknown: ++counters.malformed; break;
    }
  }

  void tracker_message(lo_message msg, detail::TrackerSource source) {
    std::string_view serial;
    UnityTransform t;
    if (!read_transform(msg, opt.unit_tolerance, serial, t) || serial.empty()) {
      ++counters.malformed;
      return;
    }
    const reference::TrackerPose pose = to_internal(t);
    const reference::TrackerPose& head = tracker[reference::index(Tracker::head)];
    const std::optional<Tracker> role = roles.role(serial, source, pose, head.valid ? &head : nullptr);
    if (!role) {
      ++counters.unassigned;
      return;
    }
    tracker[reference::index(*role)] = pose;
    tracker_now[reference::index(*role)] = true;
    frame_has_pose = true;
  }

  // The end of a frame: hand it out if it carried a pose.
  void complete() {
    if (frame_has_pose) {
      if (opt.mode == ReceiverMode::performer) {
        build_body();
        learn_skeleton();
      } else {
        build_trackers();
      }
      frame.arrival_us = arrival_us;
      frame.sender_time_s = status.time_s;
      frame.skeleton_ready = skeleton.has_value();
      ++counters.frames;
      if (handler) {
        try {
          handler(frame);
        } catch (...) {
          ++counters.handler_exceptions;
        }
      }
    }
    frame_has_pose = false;
    root_now = false;
    upper_chest_now = false;
    now.fill(false);
    tracker_now.fill(false);
  }

  // Unity's UpperChest is folded into tonus's Chest: Chest * UpperChest is
  // the frame the neck and shoulders hang from, so their local rotations
  // (relative to UpperChest) stay right.
  sim::Quat chest_local() const {
    const std::size_t c = sim::index(Bone::Chest);
    const sim::Quat chest = seen[c] ? local[c].rot : sim::Quat::Identity();
    return upper_chest_seen ? (chest * upper_chest.rot).normalized() : chest;
  }

  void build_body() {
    reference::BodySample& s = frame.body;
    for (std::size_t i = 0; i < kN; ++i) {
      s.present[i] = now[i];
      s.local[i] = from_unity(local[i].rot);
    }
    const std::size_t c = sim::index(Bone::Chest);
    s.present[c] = now[c] || upper_chest_now;
    s.local[c] = from_unity(chest_local());
    // The Hips joint in the sender's world: the root composed with the Hips' local pose.
    const std::size_t h = sim::index(Bone::Hips);
    s.root_present = now[h] || (root_now && seen[h]);
    s.present[h] = s.root_present;
    const sim::Quat root_rot = from_unity(root.rot);
    s.root_position = from_unity(root.pos_m) + root_rot * from_unity(local[h].pos_m);
    s.root_rotation = (root_rot * from_unity(local[h].rot)).normalized();
  }

  bool required_seen() const {
    for (const Bone b : kRequired) {
      if (!seen[sim::index(b)]) return false;
    }
    return seen[sim::index(Bone::Neck)] || seen[sim::index(Bone::Head)];
  }

  void learn_skeleton() {
    if (skeleton || !required_seen()) return;
    if (++skeleton_count < opt.skeleton_frames) return;
    reference::SourceSkeleton k;
    for (std::size_t i = 1; i < kN; ++i) {
      k.present[i] = seen[i];
      k.offset[i] = from_unity(local[i].pos_m);
    }
    k.present[0] = true;
    // Bones Unity hangs from the UpperChest: its offset joins theirs (rest rotations are identity).
    if (upper_chest_seen) {
      const sim::Vec3 uc = from_unity(upper_chest.pos_m);
      for (const Bone b : {Bone::Neck, Bone::LeftShoulder, Bone::RightShoulder}) k.offset[sim::index(b)] += uc;
      if (!seen[sim::index(Bone::Chest)]) {
        k.present[sim::index(Bone::Chest)] = true;
        k.offset[sim::index(Bone::Chest)] = uc;
      }
    }
    // Hips: straight legs standing on z = 0, the ankles kAnkleHeightShare of the leg above it.
    const auto drop = [&](Bone thigh) {
      const std::size_t t = sim::index(thigh);
      return -(k.offset[t] + k.offset[t + 1] + k.offset[t + 2]).z();
    };
    const double hip_over_ankles = 0.5 * (drop(Bone::LeftUpperLeg) + drop(Bone::RightUpperLeg));
    k.offset[0] = sim::Vec3(0.0, 0.0, hip_over_ankles * (1.0 + kAnkleHeightShare));
    skeleton = k;
  }

  void build_trackers() {
    reference::TrackerFrame& f = frame.trackers;
    f.time_s = static_cast<double>(arrival_us) * 1e-6;
    for (std::size_t i = 0; i < reference::kTrackerCount; ++i) {
      f.pose[i] = tracker[i];
      f.pose[i].valid = tracker_now[i];
    }
  }
};

VmcReceiver::VmcReceiver(const ReceiverOptions& options) : options_(options) {
  state_ = std::make_unique<State>(options_, handler_);
  if (options_.port < 0 || options_.port > 65535) {
    error_ = "VMC receive port must be 0 to 65535, got " + std::to_string(options_.port);
    return;
  }
  if (!(options_.unit_tolerance > 0.0 && options_.unit_tolerance < 0.5)) {
    error_ = "VMC unit_tolerance must be in (0, 0.5)";
    return;
  }
  sockaddr_storage addr{};
  socklen_t addr_len = 0;
  const auto port = static_cast<std::uint16_t>(options_.port);
  sockaddr_in v4{};
  sockaddr_in6 v6{};
  if (inet_pton(AF_INET, options_.address.c_str(), &v4.sin_addr) == 1) {
    v4.sin_family = AF_INET;
    v4.sin_port = htons(port);
    std::memcpy(&addr, &v4, sizeof(v4));
    addr_len = sizeof(v4);
  } else if (inet_pton(AF_INET6, options_.address.c_str(), &v6.sin6_addr) == 1) {
    v6.sin6_family = AF_INET6;
    v6.sin6_port = htons(port);
    std::memcpy(&addr, &v6, sizeof(v6));
    addr_len = sizeof(v6);
  } else {
    error_ = "VMC receive address \"" + options_.address + "\" is not a numeric IPv4 or IPv6 address";
    return;
  }
  const std::string where = options_.address + ":" + std::to_string(options_.port);
  fd_ = ::socket(addr.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    error_ = "VMC receiver: cannot open a UDP socket: " + std::string(std::strerror(errno));
    return;
  }
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), addr_len) != 0) {
    const int e = errno;
    error_ = "VMC receiver: cannot bind UDP " + where + ": " + std::strerror(e);
    if (e == EADDRINUSE) error_ += " (another VMC receiver, e.g. VirtualMotionCapture or SlimeVR, may hold the port)";
    ::close(fd_);
    fd_ = -1;
    return;
  }
  sockaddr_storage bound{};
  socklen_t bound_len = sizeof(bound);
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &bound_len) == 0) {
    port_ = bound.ss_family == AF_INET6 ? ntohs(reinterpret_cast<const sockaddr_in6*>(&bound)->sin6_port)
                                        : ntohs(reinterpret_cast<const sockaddr_in*>(&bound)->sin_port);
  }
}

VmcReceiver::~VmcReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

int VmcReceiver::receive(int timeout_ms) {
  if (fd_ < 0) return 0;
  int decoded = 0;
  try {
    if (timeout_ms > 0) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, timeout_ms) <= 0) return 0;
    }
    State& s = *state_;
    while (decoded < kMaxDatagramsPerCall) {
      const ssize_t n = ::recv(fd_, s.buffer.data(), s.buffer.size(), MSG_DONTWAIT | MSG_TRUNC);
      if (n < 0) {
        if (errno == EINTR) continue;
        break;  // nothing more waiting (or a socket error: the next call tries again)
      }
      s.arrival_us = steady_now_us();
      ++decoded;
      if (static_cast<std::size_t>(n) > s.buffer.size()) {
        ++s.counters.datagrams;
        ++s.counters.malformed;
        continue;
      }
      s.datagram(static_cast<std::size_t>(n));
    }
  } catch (...) {
    // std::bad_alloc from the tracker serials or liblo's callers: the datagram is lost, the receiver lives on.
  }
  return decoded;
}

void VmcReceiver::decode(const unsigned char* datagram, std::size_t size, std::int64_t arrival_us) {
  try {
    State& s = *state_;
    s.arrival_us = arrival_us;
    if (size > s.buffer.size()) {
      ++s.counters.datagrams;
      ++s.counters.malformed;
      return;
    }
    if (size > 0) std::memcpy(s.buffer.data(), datagram, size);
    s.datagram(size);
  } catch (...) {
    // as receive(): the datagram is lost, the receiver lives on
  }
}

const ReceiverCounters& VmcReceiver::counters() const { return state_->counters; }
const SenderStatus& VmcReceiver::sender() const { return state_->status; }
const std::optional<reference::SourceSkeleton>& VmcReceiver::skeleton() const { return state_->skeleton; }

void VmcReceiver::reset_skeleton() {
  state_->skeleton.reset();
  state_->skeleton_count = 0;
  state_->seen.fill(false);
  state_->upper_chest_seen = false;
}

const std::vector<std::pair<std::string, reference::Tracker>>& VmcReceiver::tracker_assignments() const {
  return state_->roles.assigned();
}

}  // namespace tonus::vmc
