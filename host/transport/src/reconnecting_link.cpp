#include "tonus/host/transport/reconnecting_link.hpp"

#include <algorithm>
#include <thread>

namespace tonus::host {

ReconnectingBandLink::ReconnectingBandLink(Opener open, ReconnectPolicy policy)
    : open_(std::move(open)), policy_(policy), backoff_(policy.first_retry) {}

bool ReconnectingBandLink::send(const proto::Request& req) { return link_ != nullptr && link_->send(req); }

std::uint64_t ReconnectingBandLink::total_decode_errors() const {
  return old_decode_errors_ + (link_ != nullptr ? link_->decode_errors() : 0);
}

LinkEvent ReconnectingBandLink::drop(bool stale) {
  old_decode_errors_ += link_->decode_errors();
  link_.reset();
  ++disconnects_;
  if (stale) ++stale_drops_;
  // Try again at once: a band that was only reset is usually back already.
  next_try_ = Clock::now();
  backoff_ = policy_.first_retry;
  LinkEvent e;
  e.kind = LinkEvent::Kind::disconnected;
  return e;
}

LinkEvent ReconnectingBandLink::read_event(int timeout_ms) {
  const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  for (;;) {
    const auto now = Clock::now();
    if (link_ == nullptr) {
      if (now >= next_try_) {
        std::string error;
        link_ = open_ ? open_(error) : nullptr;
        if (link_ != nullptr) {
          ++opens_;
          backoff_ = policy_.first_retry;
          last_event_ = Clock::now();
          LinkEvent e;
          e.kind = LinkEvent::Kind::reconnected;
          return e;
        }
        error_ = error;
        ++open_failures_;
        next_try_ = now + backoff_;
        backoff_ = std::min(backoff_ * 2, policy_.max_retry);
      }
      if (now >= deadline) return LinkEvent{};
      std::this_thread::sleep_until(std::min(next_try_, deadline));
      continue;
    }
    // Wake in time to notice staleness even when the caller waits long.
    const auto stale_at = last_event_ + policy_.stale_after;
    const auto wake = std::min(deadline, stale_at);
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(wake - now).count();
    LinkEvent e = link_->read_event(left > 0 ? static_cast<int>(left) : 0);
    if (e.kind == LinkEvent::Kind::closed) return drop(false);
    if (e.kind != LinkEvent::Kind::none) {
      last_event_ = Clock::now();
      return e;
    }
    if (Clock::now() >= stale_at) return drop(true);
    if (Clock::now() >= deadline) return e;
  }
}

ReconnectingBandLink::Opener hidapi_opener(std::uint16_t vid, std::uint16_t pid, std::wstring serial,
                                           HidBackend& backend) {
  return [vid, pid, serial = std::move(serial), &backend](std::string& error) -> std::unique_ptr<BandLink> {
    auto t = HidapiTransport::open(vid, pid, serial, error, backend);
    if (t == nullptr) return nullptr;
    return std::make_unique<HidBandLink>(std::move(t));
  };
}

ReconnectingBandLink::Opener socketcan_opener(std::string iface, std::uint8_t node, std::uint32_t id_base) {
  return [iface = std::move(iface), node, id_base](std::string& error) -> std::unique_ptr<BandLink> {
    auto t = SocketCanTransport::open(iface, node, error, id_base);
    if (t == nullptr) return nullptr;
    return std::make_unique<CanBandLink>(std::move(t), node, id_base);
  };
}

ReconnectingBandLink::Opener seqpacket_hid_opener(std::string path) {
  return [path = std::move(path)](std::string& error) -> std::unique_ptr<BandLink> {
    auto t = SeqpacketHidTransport::connect(path, error);
    if (t == nullptr) return nullptr;
    return std::make_unique<HidBandLink>(std::move(t));
  };
}

ReconnectingBandLink::Opener seqpacket_can_opener(std::string path, std::uint8_t node, std::uint32_t id_base) {
  return [path = std::move(path), node, id_base](std::string& error) -> std::unique_ptr<BandLink> {
    auto t = SeqpacketCanTransport::connect(path, error);
    if (t == nullptr) return nullptr;
    return std::make_unique<CanBandLink>(std::move(t), node, id_base);
  };
}

}  // namespace tonus::host
