// What the live viewer shows, as plain data: the scene (sent once per
// connection) and a frame (sent 30-60 times a second). The daemon fills
// these off the physics thread; this library turns them into the JSON the
// page reads (docs/viewer.md) and serves them. Positions are metres in
// tonus's frame (right-handed, Z up); quaternions are [x, y, z, w], as
// three.js takes them; the page turns Z up into three.js's Y up.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tonus::viewer {

using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;
using QuatXyzw = std::array<double, 4>;

struct BonePose {
  Vec3 pos{};  // world, the bone frame's origin
  QuatXyzw quat{0.0, 0.0, 0.0, 1.0};
};

// --- the scene: what does not change while a connection lives ------------

struct BoneInfo {
  std::string name;  // HumanBodyBones ("Hips", "LeftHand", ...)
  int parent = -1;   // index into Scene::bones, -1 for the root
  int group = -1;    // stiffness group (index into Scene::groups), -1: none
  BonePose rest;     // the bone frame in the world at the rest pose (a T-pose): what a VRM's bones are driven from
};

// The VRM avatar the page may load (docs/viewer.md). The server fills this
// from its ViewerConfig::vrm_file whatever the caller set: the scene says
// there is an avatar exactly when the server serves one.
struct SceneVrm {
  std::string url;   // kVrmUrl
  std::string name;  // the file's name (no folder), for the page's status line
  std::uint64_t bytes = 0;
};

// One collision shape of a bone, in the bone's frame (a capsule's segment lies
// along its local z).
struct GeomInfo {
  int bone = 0;
  std::string shape;  // "capsule", "sphere" or "box"
  double radius_m = 0.0;
  double half_length_m = 0.0;
  Vec3 half_extents_m{};  // box
  Vec3 pos{};             // in the bone frame
  QuatXyzw quat{0.0, 0.0, 0.0, 1.0};
};

struct Scene {
  std::string mode;  // "live" or "replay"
  std::vector<BoneInfo> bones;
  std::vector<GeomInfo> geoms;
  std::vector<std::string> groups;      // stiffness group names, in the order of Frame::stiffness
  std::vector<std::string> gift_bones;  // bones a gift may target (the page's pickers)
  double ground_z_m = 0.0;
  double rate_hz = 1000.0;      // physics rate
  std::optional<SceneVrm> vrm;  // set by the server (see SceneVrm)
};

// --- a frame: one instant --------------------------------------------------

struct ObjectFrame {
  std::uint32_t id = 0;  // the request's id
  std::string kind;      // "ball" (size = radius) or "cube" (size = edge)
  double size_m = 0.0;
  Vec3 pos{};
  QuatXyzw quat{0.0, 0.0, 0.0, 1.0};
};

// A contact force as an arrow: where it acts and the force on the avatar or
// object side, N (world). The page scales it.
struct ContactFrame {
  Vec3 pos{};
  Vec3 force_n{};
};

struct BandFrame {
  std::string source;  // "sim", "hid", "can", ...; "none"
  bool connected = false;
  bool live = false;  // reports arriving (not stale)
  bool calibrated = false;
  double latency_p50_ms = 0.0;  // device sample -> tick
  double latency_p99_ms = 0.0;
  std::uint64_t reports = 0;
  std::uint64_t lost = 0;
};

struct MetricsFrame {
  std::uint64_t ticks = 0;
  double tick_p50_us = 0.0;
  double tick_p99_us = 0.0;
  double tick_max_us = 0.0;
  std::uint64_t overruns = 0;
  double tracker_rate_hz = 0.0;
};

// Present while a recording plays: the page shows a timeline.
struct PlaybackFrame {
  double duration_s = 0.0;
  double position_s = 0.0;
  bool playing = false;
};

struct Frame {
  std::uint64_t tick = 0;
  double time_s = 0.0;              // physics time
  std::vector<BonePose> avatar;     // simulation B, one per Scene::bones
  std::vector<BonePose> reference;  // the reference (simulation A's target), one per Scene::bones
  std::vector<ObjectFrame> objects;
  std::vector<ContactFrame> contacts;  // at most a few dozen, the strongest
  std::optional<Vec2> zmp;             // the avatar's ZMP on the ground (centre of pressure); none when airborne
  std::vector<Vec2> support;           // the support polygon (convex, counter-clockwise), empty when airborne
  std::vector<double> stiffness;       // applied, 0..1, per Scene::groups
  bool override_active = false;
  std::string tracker_state;  // "none", "live", "held", "easing", "recovering"
  BandFrame band;
  MetricsFrame metrics;
  std::optional<PlaybackFrame> playback;
};

}  // namespace tonus::viewer
