// The avatar controller: the dual PD scheme, one fixed tick at a time.
//
//   1. the reference is checked (non-finite: the last valid one is kept),
//      clamped into the joint ranges, and compared with the last one (a jump
//      resyncs both simulations to it instead of flinging them);
//   2. simulation A (stiff drives, no objects, contact-free by default) tracks
//      it; the torque its drives applied is the feedforward tau_ff;
//   3. simulation B (weak drives whose gains follow the performer's stiffness,
//      plus tau_ff bounded by each joint's torque limit, holding the gifts)
//      steps; its pose is the output.
// Feedforward variants: A's applied torque (the paper), inverse dynamics of
// the reference with fixed-lag derivatives (no second simulation), or none.
//
// create() allocates everything; tick(), the gift calls and remove() never
// allocate, block, throw or log. docs/avatar.md explains the scheme.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tonus/host/avatar/gifts.hpp"
#include "tonus/host/avatar/reference.hpp"
#include "tonus/host/avatar/stiffness.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::avatar {

enum class Feedforward : std::uint8_t {
  simulation,        // (a) simulation A's applied torque (the paper)
  inverse_dynamics,  // (b) RNEA of the reference, velocities and accelerations from a fixed-lag smoother
  none,              // (c) PD only
};
std::string_view to_string(Feedforward f);

enum class RootControl : std::uint8_t {
  kinematic,   // the hips follow the reference exactly in A and B (VTuber setups)
  free_servo,  // B's root is simulated, pulled to the reference by a 6-DoF servo (its wrench reported)
};

enum class ContactsA : std::uint8_t { none, ground_only };

// Whether B's body touches the ground. A kinematic root carries the body, so
// feet that the reference puts into the floor would only be kicked out of it
// (a retargeted walk's heels dip by centimetres); a free root stands on it.
enum class BodyGround : std::uint8_t { automatic, on, off };  // automatic: off with a kinematic root

struct AvatarConfig {
  Feedforward feedforward = Feedforward::simulation;
  RootControl root = RootControl::kinematic;
  ContactsA contacts_a = ContactsA::none;
  BodyGround body_ground_b = BodyGround::automatic;
  StiffnessConfig stiffness = default_stiffness_config();
  // Simulation A: natural frequency per group, Hz, at this damping ratio.
  std::array<double, kGroupCount> stiff_hz{30.0, 30.0, 30.0, 30.0};
  double stiff_ungrouped_hz = 30.0;
  double stiff_damping_ratio = 1.0;
  // Root servo of B in free_servo mode: natural frequency for the whole body's mass and inertia.
  double root_servo_hz = 10.0;
  // A reference that turns a joint by more than jump_rad, or moves the root by
  // more than jump_m, within jump_window_s is a jump (60 rad/s and 25 m/s
  // sustained over 10 ms: beyond human motion, e.g. a clip's leading T-pose,
  // a tracker that reconnects): A and B are resynced to it instead of flung.
  double jump_rad = 0.6;
  double jump_m = 0.25;
  double jump_window_s = 0.01;
  // B has blown up when its kinetic energy exceeds this factor times A's plus
  // this margin; it is then reset to A's state.
  double blowup_energy_factor = 4.0;
  double blowup_energy_margin_j = 500.0;
  // Variant (b): the fixed-lag smoother's cutoff and lag (the reference is
  // followed this many ticks late).
  double id_cutoff_hz = 8.0;
  int id_lag_ticks = 60;
  // Gifts below the ground by this much are removed (they fell off the world).
  double gift_floor_m = -1.0;
};

// Empty when usable, else what is wrong.
std::string validate(const AvatarConfig& c);

// What happened this tick (bits of TickOutput::flags).
enum TickFlag : std::uint32_t {
  kReferenceInvalid = 1U << 0,  // non-finite or broken reference: the last valid one was used
  kReferenceClamped = 1U << 1,  // a joint asked for more than its range: clamped
  kReferenceJump = 1U << 2,     // a jump in the reference: A and B resynced to it
  kStiffnessInvalid = 1U << 3,  // a non-finite stiffness was ignored
  kStiffnessClamped = 1U << 4,  // a stiffness outside 0..1 was clamped
  kStiffnessRateLimited = 1U << 5,
  kFeedforwardClamped = 1U << 6,  // tau_ff bounded by a joint's torque limit
  kResetB = 1U << 7,              // B diverged or blew up: reset to A's state
  kResetA = 1U << 8,              // A diverged: resynced to the reference
  kContactOverflow = 1U << 9,     // B dropped contact points (sim capacity)
  kEventOverflow = 1U << 10,      // more contact events than TickOutput holds
  kGiftExpired = 1U << 11,        // a gift reached its lifetime or fell off the world
  kWarmingUp = 1U << 12,          // variant (b): the smoother has not filled its lag yet
};

// A gift touching a bone this tick (the contact points of one pair summed).
struct ContactEvent {
  sim::Bone bone = sim::Bone::Hips;
  GiftId gift;
  double impulse_ns = 0.0;  // normal impulse on the bone this tick, N*s
  sim::Vec3 point = sim::Vec3::Zero();
  sim::Vec3 normal = sim::Vec3::UnitZ();  // towards the bone
};
inline constexpr std::size_t kMaxContactEvents = 32;
inline constexpr std::size_t kMaxJumpWindowTicks = 64;  // jump_window_s / dt, at most

struct TickInput {
  ReferencePose reference;
  std::array<double, kGroupCount> stiffness{0.5, 0.5, 0.5, 0.5};
};

// Counters over the controller's life.
struct AvatarStats {
  std::uint64_t ticks = 0;
  std::uint64_t reference_invalid = 0;
  std::uint64_t reference_clamped = 0;
  std::uint64_t reference_jumps = 0;
  std::uint64_t stiffness_invalid = 0;
  std::uint64_t stiffness_clamped = 0;
  std::uint64_t feedforward_clamped = 0;
  std::uint64_t resets_a = 0;
  std::uint64_t resets_b = 0;
  std::uint64_t gifts_spawned = 0;
  std::uint64_t gifts_refused = 0;
  std::uint64_t gifts_expired = 0;
  std::uint64_t event_overflow = 0;
};

struct TickOutput {
  double time_s = 0.0;
  std::uint32_t flags = 0;
  // B's pose: the model's qpos / qvel (root + joints), and world bone frames.
  std::array<double, sim::kMaxQpos> qpos{};
  std::array<double, sim::kMaxDofs> qvel{};
  std::array<sim::Pose, sim::kBoneCount> bones{};
  // The reference B followed this tick (after checks and clamping; variant (b): delayed by its lag).
  std::array<double, sim::kMaxQpos> reference_qpos{};
  // Per bone: angle between B's joint rotation and the reference's, rad (hinges: |difference|).
  std::array<double, sim::kBoneCount> deviation_rad{};
  // Applied drive torques per dof (PD + feedforward), N*m.
  std::array<double, sim::kMaxDofs> tau_a{};
  std::array<double, sim::kMaxDofs> tau_b{};
  std::array<double, sim::kMaxDofs> tau_ff{};   // what B was fed
  std::array<double, kGroupCount> stiffness{};  // applied (rate-limited)
  // The wrench holding B's root (kinematic: absorbed; free: the servo's), world.
  sim::Vec3 root_force = sim::Vec3::Zero();
  sim::Vec3 root_torque = sim::Vec3::Zero();
  std::array<ContactEvent, kMaxContactEvents> events{};
  int nevents = 0;
};

class AvatarController {
 public:
  struct Created;
  // Checks the config against the model (a free root, the humanoid's bones for
  // the gifts' targets), allocates A, B and the scratch. The model must
  // outlive the controller.
  static Created create(const sim::Model& model, const AvatarConfig& config);

  // One fixed tick of model.timestep_s.
  const TickOutput& tick(const TickInput& in);

  SpawnResult throw_ball(const ThrowBall& spec);
  SpawnResult drop_cube(const DropCube& spec);
  GiftError remove(GiftId id);
  void clear_gifts();
  [[nodiscard]] int gift_count() const;

  // A and B to this reference at rest, gifts kept (also what a jump does).
  void resync(const ReferencePose& ref);
  // Applied stiffness set at once (no rate limit): experiments and start-up.
  void set_stiffness_now(const std::array<double, kGroupCount>& s);

  [[nodiscard]] const TickOutput& output() const { return out_; }
  [[nodiscard]] const AvatarStats& stats() const { return stats_; }
  [[nodiscard]] const sim::Model& model() const { return *model_; }
  [[nodiscard]] const sim::Data& sim_a() const { return *a_; }
  [[nodiscard]] const sim::Data& sim_b() const { return *b_; }
  [[nodiscard]] const AvatarConfig& config() const { return config_; }
  [[nodiscard]] const StiffnessMapper& mapper() const { return mapper_; }

  ~AvatarController();
  AvatarController(AvatarController&&) noexcept;
  AvatarController& operator=(AvatarController&&) noexcept;
  AvatarController(const AvatarController&) = delete;
  AvatarController& operator=(const AvatarController&) = delete;

 private:
  AvatarController(const sim::Model& model, const AvatarConfig& config);
  SpawnResult spawn(const sim::ObjectSpec& spec, double lifetime_s);  // a checked gift into B
  struct Impl;

  const sim::Model* model_;
  AvatarConfig config_;
  StiffnessMapper mapper_;
  std::unique_ptr<sim::Data> a_;
  std::unique_ptr<sim::Data> b_;
  std::unique_ptr<Impl> impl_;
  TickOutput out_;
  AvatarStats stats_;
};

struct AvatarController::Created {
  std::optional<AvatarController> controller;
  std::string error;
  explicit operator bool() const { return controller.has_value(); }
};

}  // namespace tonus::avatar
