// The streaming balance filter (issue 14's online variant): frames go in one
// at a time, each comes out corrected `lookahead` frames later, and nothing
// after that bound is ever used.
//
// Per frame:
// - the segments' centres of mass go through fixed-lag smoothers
//   (derivatives::FixedLag3, the analysis' own Kalman smoother run causally),
//   which give positions and accelerations for every frame of the window, the
//   newest on the filter alone, the oldest on the full look-ahead;
// - contacts and the ground come from CausalContacts (this frame and the ones
//   before it only);
// - every frame of the window gets its particle ZMP and support polygon, and
//   the ZMP error: how far the ZMP must move to lie `margin` inside (zero where
//   it already does, where no foot is down, and where the ZMP is undefined);
// - preview control on the cart-table model plans a centre-of-mass offset
//   whose cart ZMP (offset - z_c / g * its acceleration) keeps every frame of
//   the window inside its polygon (each edge a half-plane, as are the shift
//   cap and each leg's reach; both axes at once): it starts moving before the
//   error arrives and eases out after (Kajita's plain preview, one reference
//   move per frame and axis, with constraint_weight 0);
// - the offset becomes a horizontal pelvis shift (the feet stay: the legs are
//   re-solved by the same two-bone IK as the offline filters), divided by the
//   share of the body's mass that moves with the pelvis at that frame and
//   capped.
// The result stays the offline filters' kind of edit (apply_correction writes
// it into a BVH clip); tests/balance/test_online_filter.cpp states how far it
// lands from the offline one.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tonus/host/balance/analysis.hpp"
#include "tonus/host/balance/preview_control.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"

namespace tonus::balance::detail {
class ConstrainedPreview;
class DropEnvelope;
}  // namespace tonus::balance::detail

namespace tonus::balance {

inline constexpr double kMaxLookahead_s = 0.25;  // the bound

struct OnlineOptions {
  // Body mass and sex, contact thresholds, gravity, and the smoothing's other
  // parameters; its cut-off is the window's own (below).
  AnalysisOptions analysis;
  // The window's smoothers' -6 dB frequency, Hz. Higher than the offline
  // analysis's 6 Hz: the estimators that judge the result run from 4 to 12 Hz,
  // and a window that sees what the 8-12 Hz ones see leaves fewer frames
  // outside under the family's worst member on five shared clips of six
  // (measured 4-12 Hz, docs/balance.md "The window's cut-off").
  double window_cutoff_hz = 10.0;
  double dt_s = 1.0 / 120.0;
  double lookahead_s = 0.25;  // (0, kMaxLookahead_s]
  double margin_m = 0.015;    // the ZMP is brought this far inside its polygon
  double max_shift_m = 0.08;  // the pelvis's horizontal shift, either axis
  // A fine layer of pelvis shift, at most this much per axis, that takes
  // capture jitter out of what the ZMP sees: it moves the segments' centres of
  // mass, weighted by mass and height above the ground (the ZMP's
  // acceleration term), onto the smoothers' estimate at full look-ahead, the
  // path the ZMP errors were computed on (0: off). The robust filter's fine
  // layer, online.
  double max_fine_shift_m = 0.005;
  // Where the cap or a straight leg holds the shift back, the preview's cart
  // goes on from the shift applied, not the one asked for (false: it winds
  // up, and overshoots when the limit lets go).
  bool anti_windup = true;
  double jerk_weight = 1e-6;  // preview control's R / Q (Kajita's)
  // The planner (host/balance/src/constrained_preview.hpp): the support
  // polygons ahead, the shift cap and each leg's reach are half-planes on the
  // plan, and this weights a violation's square against the ZMP tracking's.
  // 0: Kajita's plain preview, one reference move per frame (what this filter
  // was until 2026-12-04; measured against the planner in docs/balance.md).
  double constraint_weight = 20.0;
  double com_height_m = 0.9;  // the cart-table's height: the centre of mass above the ground, standing
};

// One corrected frame.
struct OnlineFrame {
  std::size_t index = 0;  // which pushed frame (0 = the first)
  MotionFrame corrected;
  Vec2 shift_m = Vec2::Zero();       // the pelvis's horizontal shift applied (the fine layer included)
  Vec2 fine_shift_m = Vec2::Zero();  // of it, the fine layer
  std::array<FootContact, 2> contacts{};
  bool zmp_defined = false;
  Vec2 zmp_before = Vec2::Zero();  // the input's ZMP as the window saw it
  double outside_before_m = 0.0;   // its signed distance to the support polygon (> 0 outside); 0 when airborne
  double share = 0.0;              // of the shift, what the centre of mass follows
  double drop_m = 0.0;             // the pelvis lowered for a straight leg to keep reaching its foot, eased over time
  bool shift_capped = false;       // the shift wanted more than max_shift_m
  bool reachable = true;           // false: a leg could not reach its foot (the foot moved)
};

class OnlineBalance {
 public:
  struct Created;
  // Refuses a look-ahead outside (0, 0.25] s or under one frame, a dt, margin,
  // cap or height that is not finite and positive, and smoothing parameters
  // the derivatives library refuses. Everything is allocated here (the
  // preview gains solved); push allocates only when a sole is measured again.
  static Created create(const OnlineOptions& options);
  OnlineBalance(OnlineBalance&&) noexcept;
  OnlineBalance& operator=(OnlineBalance&&) noexcept;
  ~OnlineBalance();

  // Feeds the next frame. Once more than the look-ahead has arrived, fills
  // `out` with the frame `lookahead_frames()` before this one and returns true.
  // A frame with a non-finite landmark is taken as the previous one (counted).
  bool push(const MotionFrame& frame, OnlineFrame& out);
  // At the end of a stream: the frames still held, one per call, with the
  // errors beyond the last frame taken as held; false when none is left.
  bool flush(OnlineFrame& out);

  [[nodiscard]] std::size_t lookahead_frames() const { return lag_; }
  [[nodiscard]] std::size_t pushed() const { return pushed_; }
  [[nodiscard]] std::size_t non_finite_frames() const { return non_finite_; }
  [[nodiscard]] const CausalContacts& contacts() const { return contacts_; }

 private:
  OnlineBalance(const OnlineOptions& options, std::size_t lag, const derivatives::FixedLag3& smoother,
                PreviewModel preview);
  void plan_rows(std::size_t w, std::size_t held);
  void window_errors();
  void emit(std::size_t frames_back, OnlineFrame& out);
  [[nodiscard]] Vec2 fine_shift(const MotionFrame& f, const SegmentFrame& captured, const SegmentFrame& smoothed,
                                const Vec2& shift) const;

  OnlineOptions options_;
  std::size_t lag_;
  MassModel mass_;
  CausalContacts contacts_;
  std::vector<derivatives::FixedLag3> segments_;  // one per mass part
  PreviewModel preview_;
  std::unique_ptr<detail::ConstrainedPreview> planner_;  // null: the plain preview
  // The drop eased over time (drop_envelope.hpp): each frame's need, the
  // emitted ones as applied (a ring over the envelope's reach), the ones
  // ahead predicted under the shift of the frame going out.
  std::unique_ptr<detail::DropEnvelope> drop_envelope_;
  std::vector<double> past_need_;
  std::vector<double> need_window_;
  std::array<double, 2> drop_state_{};  // the drop applied last (m) and its rate (m/s)
  std::array<Eigen::Vector3d, 2> cart_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  // x, y offsets
  // Rings over the window (lag + 1 frames), frame k at k % (lag + 1).
  std::vector<MotionFrame> frames_;
  std::vector<std::array<FootContact, 2>> frame_contacts_;
  std::vector<SegmentFrame> placed_;            // the segments as captured
  std::vector<ConvexPolygon> polygons_;         // the support polygon, from the contacts known when it arrived
  std::vector<derivatives::Estimate3> window_;  // per mass part, its smoother's window (frames back 0 .. lag)
  // Per window position (0 = the oldest): the ZMP error ahead, per axis.
  std::array<std::vector<double>, 2> errors_;
  std::vector<Vec2> zmp_;
  std::vector<double> ratio_;  // per window position: the support ratio, 0.2 to 3 (the errors' weight: at most 1)
  std::vector<double> outside_;
  std::vector<bool> defined_;
  double share_ = 0.0;  // of a pelvis shift, what the centre of mass follows (measured on the first frame out)
  std::size_t pushed_ = 0;
  std::size_t emitted_ = 0;
  std::size_t non_finite_ = 0;
};

struct OnlineBalance::Created {
  std::string error;
  std::optional<OnlineBalance> filter;
  explicit operator bool() const { return error.empty(); }
};

// A whole clip streamed through the filter, frame by frame, as a live source
// would feed it: every frame comes out exactly as it would have live (nothing
// beyond the look-ahead is used), so a clip known in advance can be corrected
// at load and played.
struct OnlineRun {
  HumanMotion corrected;
  std::vector<Vec2> shift_m;   // per frame
  std::vector<double> drop_m;  // per frame: the pelvis lowered (apply_correction's drop_m)
  double max_drop_m = 0.0;
  std::size_t lookahead_frames = 0;
  double mean_push_us = 0.0, max_push_us = 0.0;  // the cost of push(), wall clock
  std::string error;                             // the options were refused; nothing ran
  [[nodiscard]] bool ok() const { return error.empty(); }
};
OnlineRun run_online(const HumanMotion& motion, const OnlineOptions& options);

}  // namespace tonus::balance
