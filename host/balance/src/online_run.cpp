#include <algorithm>
#include <chrono>

#include "tonus/host/balance/online_filter.hpp"

namespace tonus::balance {

OnlineRun run_online(const HumanMotion& motion, const OnlineOptions& options) {
  OnlineRun run;
  auto created = OnlineBalance::create(options);
  if (!created) {
    run.error = created.error;
    return run;
  }
  OnlineBalance& filter = *created.filter;
  run.corrected = motion;
  run.shift_m.assign(motion.size(), Vec2::Zero());
  run.drop_m.assign(motion.size(), 0.0);
  run.lookahead_frames = filter.lookahead_frames();
  OnlineFrame out;
  // A leading T-pose is not part of the motion: fed to the filter it would
  // set the contacts' ground and the smoothers' first frames (it stays as it is).
  const std::size_t first = std::min(motion.first_frame, motion.size());
  const auto take = [&] {
    run.corrected.frames[first + out.index] = out.corrected;
    run.shift_m[first + out.index] = out.shift_m;
    run.drop_m[first + out.index] = out.drop_m;
    run.max_drop_m = std::max(run.max_drop_m, out.drop_m);
  };
  double total_us = 0.0;
  for (std::size_t t = first; t < motion.size(); ++t) {
    const MotionFrame& frame = motion.frames[t];
    const auto t0 = std::chrono::steady_clock::now();
    const bool got = filter.push(frame, out);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    total_us += us;
    run.max_push_us = std::max(run.max_push_us, us);
    if (got) take();
  }
  while (filter.flush(out)) take();
  const std::size_t pushed = motion.size() - first;
  run.mean_push_us = pushed > 0 ? total_us / static_cast<double>(pushed) : 0.0;
  return run;
}

}  // namespace tonus::balance
