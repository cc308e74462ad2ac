// The scenes of tonus-bench-physics, built with tonus::sim and exported to
// MJCF, so tonus and MuJoCo start from the same bodies in the same places.
//
// Every scene is the default humanoid standing on the ground with 40 Hz
// drives (it holds its T-pose like a statue) plus free objects; dt = 1 ms.
//   static     a 1 kg 8 cm cube on the left hand.
//   lively     static, plus a 0.4 kg ball (r 6 cm, restitution 0.5) thrown at
//              the chest at 6 m/s from 1 m behind it, re-thrown every 400 steps
//              (from the front, the hits tip the statue over its heels).
//   pile<N>    N boxes (8 cm, 0.5 kg): up to four on the hands (two per hand),
//              the rest stacked two high in a ring around the feet, ~1 cm apart.
//   shower<N>  N balls (r 4 cm, 0.1 kg, restitution 0.3) dropped from 2-3.5 m
//              over the avatar; ball k is dropped again every 1500 steps, 15 k
//              steps after ball 0, whatever it is doing (a fixed schedule, so
//              both engines see the same drops at the same steps).
// Objects are "put back" (teleported) by a Schedule that both engines apply
// before the same step indices, counted from the first settling step.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tonus/sim/data.hpp"
#include "tonus/sim/inputs.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::bench {

enum class SceneKind : std::uint8_t { statue, lively, pile, shower };

struct SceneSpec {
  std::string name;  // BM_Tonus/<name>
  SceneKind kind = SceneKind::statue;
  int count = 0;  // boxes (pile) or balls (shower)
  int settle_steps = 500;
};

// The five scenes the goals are stated on: static, lively, pile20, pile50, shower100.
std::vector<SceneSpec> benchmark_scenes();
// A pile of `boxes` boxes (0 allowed), named "boxes<N>": the scaling runs.
SceneSpec pile_scene(int boxes);

// An object set to a pose and velocity (angular velocity zero) between steps.
struct Teleport {
  int slot = -1;
  sim::Vec3 pos = sim::Vec3::Zero();
  sim::Quat quat = sim::Quat::Identity();
  sim::Vec3 lin_vel = sim::Vec3::Zero();
};

// Which objects are put back before a step. Computed on the fly (no
// allocation), so it can run inside the timed loops.
class Schedule {
 public:
  Schedule() = default;                              // nothing is ever put back
  static Schedule throws(const Teleport& start);     // lively
  static Schedule drops(int count, int first_slot);  // shower
  // Calls fn(const Teleport&) for every object put back before step `step`.
  template <class Fn>
  void at(std::int64_t step, Fn&& fn) const {
    if (kind_ == SceneKind::lively && step % kThrowEvery == 0) fn(throw_);
    if (kind_ == SceneKind::shower && step > 0) {
      const std::int64_t r = step % kDropEvery;
      if (r % kDropSpacing == 0 && r / kDropSpacing < count_)
        fn(drop(static_cast<int>(r / kDropSpacing), step / kDropEvery));
    }
  }

  static constexpr std::int64_t kThrowEvery = 400;  // lively
  static constexpr std::int64_t kDropEvery = 1500;  // shower: each ball ...
  static constexpr std::int64_t kDropSpacing = 15;  // ... ball k this many steps after ball k - 1

  // Ball k's n-th drop (n = 0: where it starts): a jittered cell of a 5 x 5
  // grid over the avatar, at its height layer; the jitter differs per drop.
  [[nodiscard]] Teleport drop(int k, std::int64_t n) const;

 private:
  SceneKind kind_ = SceneKind::statue;
  int count_ = 0;
  int first_slot_ = 0;  // shower: ball k lives in slot first_slot_ + k
  Teleport throw_;      // lively: the ball's start state
};

struct TonusScene {
  SceneSpec spec;
  std::unique_ptr<sim::Model> model;
  std::unique_ptr<sim::Data> data;
  sim::StepInputs inputs;
  Schedule schedule;
  std::int64_t next_step = 0;  // index of the next step, counted from the first settling step
  std::string mjcf;            // MuJoCo's copy, exported before the first step
  std::string error;           // non-empty: the scene could not be built (names the scene)

  // The schedule's teleports before step next_step (not timed by the benchmarks).
  void put_back();
  // put_back(), one step, next_step + 1.
  void advance();
  void settle() {
    while (next_step < spec.settle_steps) advance();
  }
};

// Builds a scene at its initial state (not settled) and exports its MJCF
// (drives as joint springs, the objects as free bodies in slot order).
TonusScene make_scene(const SceneSpec& spec);

// The standing humanoid every scene uses (40 Hz drives); exits on failure.
std::unique_ptr<sim::Model> standing_humanoid();

}  // namespace tonus::bench
