// A band link that survives unplugging: it notices a closed link (the
// transport reports it gone) or a stale one (no event for `stale_after`),
// drops it, and reopens it on its own with exponential backoff. One
// SequenceTracker spans the reconnections, so a band that kept running while
// the link was down shows as loss, and one that rebooted as a restart.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "tonus/host/transport/band_link.hpp"

namespace tonus::host {

struct ReconnectPolicy {
  std::chrono::milliseconds first_retry{50};    // after a failed open
  std::chrono::milliseconds max_retry{2000};    // the backoff doubles up to this
  std::chrono::milliseconds stale_after{2000};  // no event at all for this long: reopen
};

class ReconnectingBandLink final : public BandLink {
 public:
  // Opens a fresh link (owning its transport), or nullptr with `error` set.
  using Opener = std::function<std::unique_ptr<BandLink>(std::string& error)>;

  explicit ReconnectingBandLink(Opener open, ReconnectPolicy policy = {});

  bool send(const proto::Request& req) override;  // false while no link is open
  // Never Kind::closed: a lost link gives Kind::disconnected, a new one Kind::reconnected.
  LinkEvent read_event(int timeout_ms) override;

  [[nodiscard]] bool connected() const { return link_ != nullptr; }
  [[nodiscard]] const std::string& last_error() const { return error_; }
  [[nodiscard]] std::uint64_t open_failures() const { return open_failures_; }
  [[nodiscard]] std::uint64_t stale_drops() const { return stale_drops_; }

 protected:
  [[nodiscard]] std::uint64_t total_decode_errors() const override;
  [[nodiscard]] std::uint64_t disconnects() const override { return disconnects_; }
  [[nodiscard]] std::uint64_t reconnects() const override { return opens_ > 0 ? opens_ - 1 : 0; }

 private:
  using Clock = std::chrono::steady_clock;
  LinkEvent drop(bool stale);

  Opener open_;
  ReconnectPolicy policy_;
  std::unique_ptr<BandLink> link_;
  Clock::time_point next_try_{};
  Clock::time_point last_event_{};
  std::chrono::milliseconds backoff_;
  std::string error_;
  std::uint64_t opens_ = 0;
  std::uint64_t open_failures_ = 0;
  std::uint64_t disconnects_ = 0;
  std::uint64_t stale_drops_ = 0;
  std::uint64_t old_decode_errors_ = 0;  // of the links already dropped
};

// Openers for the usual links. The hidapi one enumerates afresh at every
// attempt, so a band replugged on another hidraw node is found again.
ReconnectingBandLink::Opener hidapi_opener(std::uint16_t vid, std::uint16_t pid, std::wstring serial = {},
                                           HidBackend& backend = hidapi_backend());
// `id_base`: the band's DeviceConfig.can_id_base (0 = the 11-bit id plan).
ReconnectingBandLink::Opener socketcan_opener(std::string iface, std::uint8_t node, std::uint32_t id_base = 0);
// tonus-band-sim --hid-socket PATH / --can-socket PATH.
ReconnectingBandLink::Opener seqpacket_hid_opener(std::string path);
ReconnectingBandLink::Opener seqpacket_can_opener(std::string path, std::uint8_t node, std::uint32_t id_base = 0);

}  // namespace tonus::host
