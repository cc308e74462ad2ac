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
  run.lookahead_frames = filter.lookahead_frames();
  OnlineFrame out;
  const auto take = [&] {
    run.corrected.frames[out.index] = out.corrected;
    run.shift_m[out.index] = out.shift_m;
    run.max_drop_m = std::max(run.max_drop_m, out.drop_m);
  };
  double total_us = 0.0;
  for (const MotionFrame& frame : motion.frames) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool got = filter.push(frame, out);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    total_us += us;
    run.max_push_us = std::max(run.max_push_us, us);
    if (got) take();
  }
  while (filter.flush(out)) take();
  run.mean_push_us = motion.size() > 0 ? total_us / static_cast<double>(motion.size()) : 0.0;
  return run;
}

}  // namespace tonus::balance
