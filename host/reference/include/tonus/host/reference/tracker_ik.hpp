// Full-body poses from 3 trackers (head + hands) or 6 (+ waist + feet), in
// the spirit of Final IK's VRIK: analytic, a few microseconds, no allocation.
//
// Per frame:
//   1. Each tracker's sample is checked (finite, unit, plausible) and turned
//      into its bone's pose through the calibration offset. A lost tracker is
//      held, then eased to a neutral pose; a returning one is blended back.
//   2. Trunk. 3 points: the body's heading from the head's facing and the
//      hands; the head's tilt shared out down the neck, chest, spine and
//      pelvis; the pelvis placed where that chain puts the head exactly on its
//      tracker, so crouching and leaning come out of the head's height.
//      6 points: the pelvis from the waist tracker, the spine and chest
//      turned as one piece so the neck reaches the head (closed form).
//   3. Arms: the clavicle raised toward a high or far hand; two-bone arms that
//      put the wrist on the tracker, the elbow on the side away from where the
//      hand points (least wrist bend), or toward an elbow tracker.
//   4. Legs: 6 points, two-bone legs to the foot trackers, knees toward the
//      feet's facing (or knee trackers). 3 points, procedural steps: each foot
//      stays planted until the pelvis has moved or turned past a threshold,
//      then steps, one at a time, toward where the moving pelvis will need it.
//   5. Every joint is put into the humanoid's range (sim/joint_limits.hpp);
//      quaternions stay in the previous frame's hemisphere.
//
// The humanoid must be sim/humanoid.hpp's, built for the performer
// (calibrated_spec) so its bones match the calibration.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "tonus/host/reference/calibration.hpp"
#include "tonus/host/reference/one_euro.hpp"
#include "tonus/host/reference/trackers.hpp"
#include "tonus/sim/capacity.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference {

struct IkOptions {
  // Trunk (3 points): the share of the head's rotation (relative to the
  // body's heading) each trunk bone takes, in world terms, pelvis to neck.
  double pelvis_share = 0.0;
  double spine_share = 0.12;
  double chest_share = 0.25;
  double neck_share = 0.6;
  double hands_heading_weight = 0.3;       // the hands' say in the body's heading, against the head's 1
  double heading_smoothing_s = 0.02;       // time constant of that heading, 3 points (0: none) ...
  double heading_smoothing2_s = 0.02;      // ... then of a second stage after it (3 points only; 0: none)
  double waist_heading_smoothing_s = 0.1;  // ... and 6 points (it only shapes the trunk the waist carries)
  double trunk_smoothing_s = 0.05;         // time constant of the head turn the trunk bones share (0: none)
  double trunk_follows_pelvis = 0.5;       // 6 points: the share of the waist tracker's turn (about the vertical) the
                                           // spine and chest take ...
  double trunk_tilts_with_pelvis = 0.25;   // ... and of its tilt and roll
  // 6 points: the spine and chest's turn about the vertical from the waist
  // tracker's saturates smoothly (tanh) toward this: the thorax turns against
  // the pelvis only so far (a kick's head looking 60 degrees off the hips is
  // the neck's turn), and the head's share dragged the chest off in spins.
  // 0: no limit.
  double trunk_turn_limit_rad = 0.5;
  // 6 points: the neck joint goes to the side of the spine-to-head line the
  // guessed trunk names, pulled behind it by this (times the trunk's length):
  // an upright trunk and neck are nearly in line and the guess alone let the
  // neck joint swing across with the head's sway.
  double neck_back_pole_weight = 0.1;
  // Arms.
  double clavicle_share = 0.08;        // of the swing that would point the clavicle at the hand
  double clavicle_raise_share = 0.25;  // added in proportion to how far above the shoulder the hand is
  double clavicle_lower_s = 0.07;      // a clavicle lowers with this time constant (raises at once; 0: at once)
  // The chest twists (about its line to the neck) toward a hand beyond this
  // times the arm's reach from its shoulder (a hanging arm is about at full
  // reach), by what brings the shoulder back to the arm's reach, at most
  // chest_twist_max_rad, through two first-order stages of
  // chest_twist_smoothing_s.
  double chest_twist_reach_factor = 1.04;
  double chest_twist_max_rad = 0.8;
  double chest_twist_smoothing_s = 0.07;
  // A hand flung outward faster than chest_twist_lead_speed_mps (its speed
  // away from the shoulder, smoothed over chest_twist_lead_smoothing_s) is
  // taken chest_twist_lead_s times the excess further out for the twist: the
  // two stages delay the twist by about their time constants, and a kick's
  // flung arm was past the reach before the chest turned. A hand swinging
  // (a walk) or slower is taken where it is.
  double chest_twist_lead_s = 0.07;
  double chest_twist_lead_speed_mps = 1.0;
  double chest_twist_lead_smoothing_s = 0.02;
  double default_pole_weight = 0.25;  // elbows: the anatomical pole (down, back) against the hand's
  double elbow_stay_weight = 3.0;     // a bent arm's elbow kept on its last side, against the smoothed cue's 1
  double elbow_roll_weight = 0.5;     // elbows: the hand's roll (the elbow's axis, least wrist twist) against it
  double arm_softness_m = 0.002;      // soft reach near a straight arm (the wrist short by at most 0.37 of it)
  double leg_softness_m = 0.0;        // ... and leg, always (0: a standing leg straight, its foot on the floor)
  // Procedural feet (3 points) only: a soft reach that fades in with the
  // pelvis's horizontal speed, full at stride_soft_speed_mps. Near a straight
  // leg the knee moves as the square root of the slack, so a walking pelvis
  // that straightens the stance leg jerks the knee; soft, the heel rises a
  // little instead. Standing still it fades out (over stride_soft_fade_s), so
  // a standing leg is straight and its foot exactly on the floor.
  double stride_softness_m = 0.12;
  double stride_soft_speed_mps = 0.3;
  double stride_soft_fade_s = 0.15;
  double elbow_smoothing_s = 0.05;  // time constant of the elbows' pole (0: none)
  double knee_smoothing_s = 0.05;   // ... and the knees'
  // ... and the knees' over a tracked foot, whose left axis names the knee's
  // plane but rolls with the ankle (a run's swing foot: 50 ms passed that on)
  double tracked_knee_smoothing_s = 0.15;
  // Steps (3 points).
  double step_threshold_m = 0.12;  // a planted foot further than this from its place under the hip steps
  double step_turn_rad = 0.6;      // ... or turned further than this from the pelvis's heading
  // A planted foot keeps its heading while the pelvis turns up to this from
  // it; further, it pivots about its ankle, the pelvis's turn from it
  // saturating smoothly toward start + width (0: never pivots), so a body
  // spinning faster than it steps does not twist the legs into their ranges.
  double foot_pivot_start_rad = 0.3;
  double foot_pivot_width_rad = 0.2;
  double step_time_s = 0.45;      // one step's swing at standing pace
  double step_time_min_s = 0.38;  // when walking fast (a swing takes about 0.4 s at any pace)
  double step_lift_m = 0.05;      // swing height (the arc is much of a swing's jerk)
  // A foot lands this far ahead of the moving pelvis. Half a stance (about
  // 0.33 s) would make a walk's stride, but 3 points do not say which foot
  // stands, and a stride in the wrong phase is a step length off: shorter
  // steps are the better guess (measured on real walks, docs/reference.md).
  double step_lead_s = 0.1;
  // A swing lands where its place will be when it lands (the pelvis's
  // velocity carried over the swing), so the foot comes down at rest rather
  // than at the pelvis's speed. That point follows the prediction with this
  // time constant, the following fading out toward touch-down; a pelvis that
  // slows to under 0.4 of the step's starting speed pulls it in at once.
  double landing_follow_s = 0.15;
  double velocity_time_constant_s = 0.1;  // smoothing of the pelvis's speed
  // Input smoothing: the 1-euro filter (Casiez et al. 2012) on every tracker
  // sample, for noisy trackers. Off by default: it adds lag (about
  // 1 / (2 pi cutoff) at rest, less moving).
  bool input_filter = false;
  OneEuroParams filter;
  // Lost trackers.
  double hold_s = 0.25;    // a lost tracker is held this long ...
  double ease_s = 0.5;     // ... then eased to its neutral over this
  double recover_s = 0.2;  // a tracker that comes back is blended in over this
  // Plausibility: a hand further than this times the arm's reach from the
  // shoulder, or a head this far above the calibrated height, is flagged.
  double implausible_reach_factor = 1.6;
};

// What a frame's solve met (bits of IkOutput::flags).
enum IkFlag : std::uint32_t {
  kIkNoHead = 1u << 0,           // the head was never seen: the rest pose, standing
  kIkTrackerInvalid = 1u << 1,   // a sample was not finite or not a rotation, and was ignored
  kIkTrackerHeld = 1u << 2,      // a lost tracker is being held
  kIkTrackerEased = 1u << 3,     // a lost tracker is being eased to its neutral
  kIkHandUnreachable = 1u << 4,  // a wrist missed its target by over 1 mm: beyond the arm, or its joint ranges
  kIkFootUnreachable = 1u << 5,  // the same for an ankle
  kIkHeadMissed = 1u << 6,       // the spine could not reach the head (6 points)
  kIkImplausible = 1u << 7,      // a hand far beyond reach, or the head far above the body's height
  kIkHandsSwapped = 1u << 8,     // the left hand is on the body's right and the right on its left
  kIkJointClamped = 1u << 9,     // a joint was put into its range
  kIkBadTime = 1u << 10,         // the frame's time went backwards or was not finite (dt taken as 0)
  kIkStepping = 1u << 11,        // a foot is in the air (3 points)
};

// How each tracker was used this frame.
enum class TrackerUse : std::uint8_t { unused, live, held, easing, neutral, recovering };

struct IkOutput {
  std::array<double, sim::kMaxQpos> qpos{};  // the humanoid's configuration (its model's layout)
  int nq = 0;
  std::uint32_t flags = 0;
  std::array<TrackerUse, kTrackerCount> use{};
  int joints_clamped = 0;
  // Distance from each wrist and the head joint to its target after the
  // solve (0 when reached), m.
  std::array<double, 2> hand_error_m{};
  double head_error_m = 0.0;
  std::array<double, 2> foot_error_m{};
  // World positions of the joints, from the solved configuration (Bone order).
  std::array<sim::Vec3, sim::kBoneCount> joint_pos{};
};

// Counters over the solver's life.
struct IkStats {
  std::uint64_t frames = 0;
  std::uint64_t invalid_samples = 0;
  std::uint64_t implausible_frames = 0;
  std::uint64_t swapped_frames = 0;
  std::uint64_t steps = 0;
  std::uint64_t clamped_frames = 0;
};

// Immutable: the humanoid's bones, the calibration and the options.
struct IkModel {
  std::array<sim::Vec3, sim::kBoneCount> offset{};    // pos_in_parent, rest frames parallel to the world
  std::array<sim::Vec3, sim::kBoneCount> rest_dir{};  // unit, towards the chain child (end bones: the twist axis)
  std::array<sim::Vec3, sim::kBoneCount> hinge_axis{};
  std::array<sim::JointLimit, sim::kBoneCount> limit{};
  std::array<sim::JointType, sim::kBoneCount> joint{};
  std::array<int, sim::kBoneCount> qpos_adr{};
  std::array<double, sim::kMaxQpos> qpos0{};  // the rest configuration
  int nq = 0;
  std::array<double, 2> upper_arm_m{}, forearm_m{}, thigh_m{}, shank_m{};  // [left, right]
  std::array<sim::Vec3, 2> ankle_in_hips{};  // the ankles' rest position in the pelvis's frame
  double ankle_height_m = 0.0;               // the ankle joint above the floor, standing
  double stature_m = 0.0;
  BodyCalibration calibration;
  IkOptions options;
};

// Mutable: what the solver carries from frame to frame.
struct IkState {
  bool started = false;
  double time_s = 0.0;
  struct Track {
    TrackerPose target;   // the bone's last valid pose
    TrackerPose shown;    // the pose used last frame (what recovery blends from)
    TrackerPose held;     // the pose shown when the tracker was lost (what easing starts from)
    OneEuroState filter;  // the input filter's memory (IkOptions::input_filter)
    double lost_s = 0.0;
    double recover_left_s = 0.0;
    bool seen = false;
  };
  std::array<Track, kTrackerCount> track{};
  double body_yaw_rad = 0.0;
  double body_yaw_stage_rad = 0.0;               // the heading's first smoothing stage (3 points)
  std::array<double, 2> clavicle_share{};        // the clavicles' last share of their turn (eased down)
  std::array<double, 2> chest_twist_rad{};       // the chest's twist toward a far hand: stage 1, stage 2
  std::array<sim::Vec3, 2> twist_hand{};         // the hands' last positions, for their speed away from the shoulder
  std::array<double, 2> twist_hand_speed{};      // ... that speed, smoothed (m/s)
  sim::Quat trunk_turn = sim::Quat::Identity();  // the head's turn from the heading, smoothed
  std::array<sim::Vec3, 2> elbow_pole{};         // in the chest's frame, smoothed, unit
  std::array<sim::Vec3, 2> elbow_last{};         // the last solved upper arm's direction, chest's frame
  std::array<sim::Vec3, 2> arm_line{};           // the last shoulder-to-wrist direction, chest's frame, unit
  std::array<sim::Vec3, 2> knee_pole{};          // in the world, smoothed, unit
  std::array<sim::Vec3, 2> leg_line{};           // the last hip-to-ankle direction, world, unit
  sim::Vec3 last_pelvis = sim::Vec3::Zero();
  sim::Vec3 pelvis_velocity = sim::Vec3::Zero();
  double stride_soft_share = 0.0;  // [0, 1]: how much of stride_softness_m the procedural legs take now
  struct Foot {
    sim::Vec3 planted = sim::Vec3::Zero();  // ankle joint position
    double yaw_rad = 0.0;                   // the heading it was planted with
    double turn_rad = 0.0;                  // the pelvis's heading less that, followed unwrapped (planted)
    sim::Vec3 from = sim::Vec3::Zero();
    double from_yaw_rad = 0.0;
    sim::Vec3 land = sim::Vec3::Zero();  // where the swing comes down (IkOptions::landing_follow_s)
    double land_yaw_rad = 0.0;           // the heading it turns to, followed without wrapping
    double start_speed_mps = 0.0;        // the pelvis's speed when the swing started
    double phase = -1.0;                 // < 0: planted; [0, 1): stepping
    double duration_s = 0.0;
  };
  std::array<Foot, 2> foot{};
  std::array<double, sim::kMaxQpos> last_qpos{};
  IkStats stats;
};

struct IkCreated {
  std::optional<IkModel> model;
  std::string error;
};

// Checks that `humanoid` is sim/humanoid.hpp's and the options are sane.
IkCreated make_ik_model(const sim::Model& humanoid, const BodyCalibration& calibration, const IkOptions& options = {});

// Solves one frame. Never throws, never allocates, never writes a NaN.
void solve_ik(const IkModel& model, IkState& state, const TrackerFrame& frame, IkOutput& out);

}  // namespace tonus::reference
