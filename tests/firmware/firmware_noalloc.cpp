// Links the whole firmware core (device, chain, calibration, NVM, synthetic
// EMG) through the self-test into a binary whose heap and exception entry
// points are poisoned (tonus_poison_heap): it would not link if any of them
// were reachable. Running it checks the self-test produced its reports.
#include <cstdio>

#include "selftest.hpp"

int main() {
  tonus::fw::SelftestResult r;
  tonus::fw::run_selftest(r);
  std::printf("self-test: %u reports, stream CRC %04x\n", static_cast<unsigned>(r.reports),
              static_cast<unsigned>(r.stream_crc));
  return r.reports == 1000 ? 0 : 1;  // 2 s at the default 500 Hz
}
