// Which foot touches the ground when, and the support polygon it spans.
//
// Each foot has two contact points, the heel and the ball (the toe joint),
// each in contact while it is low and slow, with hysteresis (it enters below
// the `on` thresholds and leaves above the `off` ones) so a foot does not
// flicker. A point that has stood still for 50 ms also lands anywhere under
// its `off` height when its foot is otherwise up, or when the foot's other
// point stands as still at the same height (within 1 cm): a flat foot on a
// floor higher than the point's resting height says (the CMU walk's floor
// rises 3 cm along the take; its feet stood flat for 0.25 s with the ball
// 2.4 cm up, and the ZMP over it, taken as a heel alone). A swing foot is
// never still, and a raised heel is not level with its ball.
// The sole is a polygon fixed to the foot, measured once from the frame where
// the foot stands flat; in contact, the part of the sole under the touching
// points supports: the whole sole, the forefoot (heel off) or the rear foot
// (heel strike). The support polygon is the convex hull of the supporting
// parts of both feet; a frame with neither foot down is airborne.
#pragma once

#include <optional>
#include <vector>

#include "tonus/host/balance/landmarks.hpp"
#include "tonus/host/balance/polygon.hpp"

namespace tonus::balance {

struct ContactOptions {
  double height_on_m = 0.025;  // above the point's own resting height
  double height_off_m = 0.040;
  double speed_on_mps = 0.30;
  double speed_off_mps = 0.60;
  std::optional<double> foot_length_m;  // sole length; default: from the skeleton's proportions
  std::optional<double> ground_z_m;     // default: estimated from the lowest foot points
};

// The sole in the foot's frame (the Foot bone's rotation), and the toes' part
// in the Toes bone's frame, relative to their joints.
struct Sole {
  std::vector<Vec3> rear;  // heel corners
  std::vector<Vec3> ball;  // corners under the toe joint (in the foot frame)
  std::vector<Vec3> toes;  // toe-tip corners (in the toes frame; relative to the toe joint)
  double length_m = 0.0;
  double width_m = 0.0;
};

struct FootContact {
  bool heel = false;
  bool ball = false;
  [[nodiscard]] bool any() const { return heel || ball; }
};

struct ContactTrack {
  double ground_z_m = 0.0;
  std::array<Sole, 2> soles;
  std::vector<std::array<FootContact, 2>> frames;  // [frame][foot]
};

// Detects contacts over a whole motion (offline: thresholds use each point's
// resting height over the clip).
ContactTrack detect_contacts(const HumanMotion& motion, const ContactOptions& options);

// The support polygon of a frame (empty when airborne), in the ground plane.
ConvexPolygon support_polygon(const ContactTrack& track, const MotionFrame& frame, std::size_t index);
// The same from the frame's contacts given directly.
ConvexPolygon support_polygon(const ContactTrack& track, const MotionFrame& frame,
                              const std::array<FootContact, 2>& contacts);
// The same into `out`, reusing its storage: allocates nothing when
// out.vertices has the capacity (kHullInlinePoints) and the soles are the
// measured ones (a few corners each).
void support_polygon(const ContactTrack& track, const MotionFrame& frame, const std::array<FootContact, 2>& contacts,
                     ConvexPolygon& out);

// The sole of one foot measured on one frame where it stands flat on the
// ground at ground_z (what detect_contacts does on the flattest frame).
Sole measure_sole(const MotionFrame& frame, Foot foot, double ground_z, const ContactOptions& options);

// Streaming contact detection for the online balance filter: each frame's
// contacts from that frame and the ones before it only. The same points,
// thresholds and hysteresis as detect_contacts, with causal estimates in place
// of the whole clip's: the ground is the 5th percentile of the lowest foot
// point over the last 1.5 s (minus the 2 cm the tracked points sit above the
// sole), each point's resting height the 5th percentile of its own heights
// over the last 1.5 s, speeds backward differences over two frames (one frame
// late), and each sole is measured again whenever its foot stands flatter than
// it has so far (low and slow), so it settles at the first flat stance. The
// still-landing rule as offline, over the last 50 ms (a floor that rises
// along the take matters more here: the past 1.5 s alone put the resting
// height too low, and the CMU walk's left forefoot stood 16 frames 0.8 mm
// over the threshold).
// Its storage is sized once (1.5 s of frames); push allocates only when it
// measures a sole again.
class CausalContacts {
 public:
  CausalContacts(const ContactOptions& options, double dt_s);
  // The contacts of this frame.
  std::array<FootContact, 2> push(const MotionFrame& frame);
  // The ground and soles so far (its `frames` stay empty).
  [[nodiscard]] const ContactTrack& track() const { return track_; }
  [[nodiscard]] std::size_t pushed() const { return pushed_; }
  // How many times a sole was measured (the only pushes that allocate).
  [[nodiscard]] std::size_t soles_measured() const { return soles_measured_; }

 private:
  struct Point {
    std::vector<double> heights;  // ring over the window
    Vec3 last = Vec3::Zero(), before_last = Vec3::Zero();
    std::size_t still = 0;  // frames in a row slower than speed_on
    bool on = false;
  };
  [[nodiscard]] double percentile_of(const std::vector<double>& ring) const;

  ContactOptions options_;
  double dt_s_;
  std::size_t window_;
  std::size_t pushed_ = 0;
  std::size_t soles_measured_ = 0;
  ContactTrack track_;
  std::vector<double> lows_;                    // ring: the lowest foot point per frame
  std::array<std::array<Point, 2>, 2> points_;  // [foot][heel, ball]
  std::array<double, 2> flattest_{};            // per foot: the best flatness score so far
  std::array<Vec3, 2> last_ankle_{}, last_ball_{};
  mutable std::vector<double> scratch_;
};

// The world sole outline of one foot at a frame (all three parts), for plots.
std::vector<Vec2> sole_outline(const ContactTrack& track, const MotionFrame& frame, Foot foot);

}  // namespace tonus::balance
