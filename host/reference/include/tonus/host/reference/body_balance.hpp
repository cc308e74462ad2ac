// The online balance filter (balance::OnlineBalance, issue 14) on a streamed
// performer body: the VMC protocol's bone rotations and root pose, before
// they are retargeted (BodyRetarget). A live source has no whole clip, so only
// the streaming filter applies: each sample comes out corrected
// `lookahead_frames()` samples later.
//
// Per sample: the sender's skeleton is posed by its own forward kinematics
// (the sample's local rotations on the skeleton's rest offsets; a bone or
// root absent or invalid keeps its last valid value, as BodyRetarget does),
// the missing extremities synthesised as for a BVH frame
// (balance::landmarks_from_bones), and the frame pushed through the filter.
// The corrected frame it gives back (the pelvis shifted, the legs re-solved
// so the feet that are down stay) is turned back into local rotations and a
// root pose: only the root and the legs change.
//
// Allocates in create() and, inside the filter, when a sole is measured
// again; push() never throws.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/reference/body_retarget.hpp"

namespace tonus::reference {

class BodyBalance {
 public:
  struct Created;
  // Refuses a skeleton without legs or forearms of some length, and options
  // the online filter refuses (the look-ahead, the sender's frame time dt_s).
  static Created create(const SourceSkeleton& skeleton, const balance::OnlineOptions& options);

  // Feeds the next sample. Once more than the look-ahead has arrived, fills
  // `out` with the sample `lookahead_frames()` before this one, corrected,
  // every bone of the skeleton present, and returns true. `frame`, when
  // given, gets what the filter did to it.
  bool push(const BodySample& sample, BodySample& out, balance::OnlineFrame* frame = nullptr);
  // At the end of a stream: the samples still held, one per call; false when none is left.
  bool flush(BodySample& out, balance::OnlineFrame* frame = nullptr);

  [[nodiscard]] std::size_t lookahead_frames() const { return filter_.lookahead_frames(); }
  [[nodiscard]] std::size_t invalid_samples() const { return invalid_; }  // samples with a value refused
  [[nodiscard]] const balance::OnlineBalance& filter() const { return filter_; }

  // The skeleton posed by `sample`'s rotations as landmarks (internal frame,
  // metres): what push() gives the filter.
  [[nodiscard]] balance::MotionFrame landmarks(const BodySample& sample) const;

 private:
  BodyBalance(const SourceSkeleton& skeleton, const balance::SkeletonGeometry& geometry, balance::OnlineBalance filter);
  bool take(const balance::OnlineFrame& frame, BodySample& out, balance::OnlineFrame* info);

  SourceSkeleton skeleton_;
  std::array<int, sim::kBoneCount> parent_{};  // nearest present ancestor; -1: none (Hips)
  balance::SkeletonGeometry geometry_;
  balance::OnlineBalance filter_;
  BodySample last_;               // every bone's and the root's last valid value
  std::vector<BodySample> held_;  // the samples in the filter's window, sample k at k % size
  balance::OnlineFrame scratch_;  // the filter's output
  std::size_t pushed_ = 0;
  std::size_t invalid_ = 0;
};

struct BodyBalance::Created {
  std::string error;
  std::optional<BodyBalance> balance;
  explicit operator bool() const { return error.empty(); }
};

}  // namespace tonus::reference
