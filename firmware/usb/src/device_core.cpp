#include "tonus/usb/device_core.hpp"

#include <algorithm>

namespace tonus::usb {

namespace {

// bmRequestType fields (USB 2.0 table 9-2)
constexpr std::uint8_t kDirIn = 0x80;
constexpr std::uint8_t kTypeMask = 0x60, kTypeStandard = 0x00, kTypeClass = 0x20;
constexpr std::uint8_t kRecipientMask = 0x1F, kRecipientDevice = 0, kRecipientInterface = 1, kRecipientEndpoint = 2;

// Standard feature selectors (table 9-6)
constexpr std::uint16_t kEndpointHalt = 0;
constexpr std::uint8_t kEp1In = 0x80U | kHidEndpoint, kEp1Out = kHidEndpoint;

// Standard requests (table 9-4)
constexpr std::uint8_t kGetStatus = 0, kClearFeature = 1, kSetFeature = 3, kSetAddress = 5, kGetDescriptor = 6,
                       kGetConfiguration = 8, kSetConfiguration = 9, kGetInterface = 10, kSetInterface = 11;
// HID class requests (HID 1.11 section 7.2)
constexpr std::uint8_t kGetReport = 1, kGetIdle = 2, kGetProtocol = 3, kSetReport = 9, kSetIdle = 10, kSetProtocol = 11;
constexpr std::uint8_t kReportTypeInput = 1, kReportTypeOutput = 2;

std::uint16_t le16(std::uint8_t lo, std::uint8_t hi) { return static_cast<std::uint16_t>(lo | (hi << 8U)); }

}  // namespace

SetupPacket SetupPacket::parse(std::span<const std::uint8_t, 8> raw) {
  return {raw[0], raw[1], le16(raw[2], raw[3]), le16(raw[4], raw[5]), le16(raw[6], raw[7])};
}

void DeviceCore::on_bus_reset() {
  configured_.store(false);
  suspended_.store(false);
  in_halted_.store(false);
  out_halted_.store(false);
  drop_input_.store(true);
  address_ = 0;
  configuration_ = 0;
  set_report_pending_ = false;
  dcd_.configure_hid_endpoints(false);
}

void DeviceCore::on_suspend() {
  suspended_.store(true);
  suspends_.fetch_add(1);
}

void DeviceCore::on_resume() {
  if (!suspended_.load()) return;
  suspended_.store(false);
  resumes_.fetch_add(1);
}

void DeviceCore::reply(std::span<const std::uint8_t> data, std::uint16_t requested) {
  // Never more than the host asked for; a short reply that fills whole packets
  // needs a zero-length packet so the host knows it ended.
  const std::size_t n = data.size() < requested ? data.size() : requested;
  const bool zlp = n < requested && n % kEp0Size == 0;
  dcd_.ep0_send(data.first(n), zlp);
}

void DeviceCore::on_setup(std::span<const std::uint8_t, 8> raw) {
  const SetupPacket s = SetupPacket::parse(raw);
  set_report_pending_ = false;
  switch (s.request_type & kTypeMask) {
    case kTypeStandard: standard_request(s); return;
    case kTypeClass: class_request(s); return;
    default: dcd_.ep0_stall(); return;
  }
}

void DeviceCore::get_descriptor(const SetupPacket& s) {
  const auto type = static_cast<std::uint8_t>(s.value >> 8U);
  const auto index = static_cast<std::uint8_t>(s.value & 0xFFU);
  switch (type) {
    case desc::device: reply(kDeviceDescriptor, s.length); return;
    case desc::configuration:
      if (index != 0) break;
      reply(kConfigurationDescriptor, s.length);
      return;
    case desc::string: {
      const std::size_t n = string_descriptor(index, serial_, ep0_buffer_);
      if (n == 0) break;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(n), s.length);
      return;
    }
    case desc::hid_report:
      if ((s.request_type & kRecipientMask) != kRecipientInterface || s.index != 0) break;
      reply(proto::hid::kReportDescriptor, s.length);
      return;
    case desc::hid:
      if ((s.request_type & kRecipientMask) != kRecipientInterface || s.index != 0) break;
      reply(std::span<const std::uint8_t>(kConfigurationDescriptor).subspan(18, 9), s.length);
      return;
    default: break;
  }
  dcd_.ep0_stall();  // e.g. device qualifier: a full-speed-only device stalls it
}

void DeviceCore::standard_request(const SetupPacket& s) {
  const std::uint8_t recipient = s.request_type & kRecipientMask;
  switch (s.request) {
    case kGetDescriptor: get_descriptor(s); return;
    case kSetAddress:
      if (recipient != kRecipientDevice || s.value > 127) break;
      address_ = static_cast<std::uint8_t>(s.value);
      dcd_.set_address(address_);
      dcd_.ep0_status();
      return;
    case kSetConfiguration:
      if (recipient != kRecipientDevice || s.value > 1) break;
      configuration_ = static_cast<std::uint8_t>(s.value);
      dcd_.configure_hid_endpoints(configuration_ == 1);
      configured_.store(configuration_ == 1);
      dcd_.ep0_status();
      return;
    case kGetConfiguration:
      ep0_buffer_[0] = configuration_;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(1), s.length);
      return;
    case kGetStatus: {
      // Device: bus powered, no remote wake-up. Endpoint: bit 0 = halted.
      const auto ep = static_cast<std::uint8_t>(s.index & 0xFFU);
      bool halted = false;
      if (recipient == kRecipientEndpoint) {
        if (ep == kEp1In) halted = in_halted_.load();
        if (ep == kEp1Out) halted = out_halted_.load();
      }
      ep0_buffer_[0] = halted ? 1 : 0;
      ep0_buffer_[1] = 0;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(2), s.length);
      return;
    }
    case kClearFeature:
    case kSetFeature: feature(s, s.request == kSetFeature); return;
    case kGetInterface:
      if (recipient != kRecipientInterface || configuration_ == 0) break;
      ep0_buffer_[0] = 0;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(1), s.length);
      return;
    case kSetInterface:
      if (recipient != kRecipientInterface || s.value != 0) break;
      dcd_.ep0_status();
      return;
    default: break;
  }
  dcd_.ep0_stall();
}

void DeviceCore::feature(const SetupPacket& s, bool set) {
  // Only ENDPOINT_HALT on EP0 (a no-op) and EP1 exists: the band has no remote
  // wake-up and is full speed only (no test modes), so other features stall.
  const auto ep = static_cast<std::uint8_t>(s.index & 0xFFU);
  if ((s.request_type & kRecipientMask) != kRecipientEndpoint || s.value != kEndpointHalt) {
    dcd_.ep0_stall();
    return;
  }
  if (ep == 0 || ep == 0x80) {
    dcd_.ep0_status();
    return;
  }
  if ((ep != kEp1In && ep != kEp1Out) || configuration_ == 0) {
    dcd_.ep0_stall();
    return;
  }
  const bool in = ep == kEp1In;
  dcd_.hid_halt(in, set);
  (in ? in_halted_ : out_halted_).store(set);
  dcd_.ep0_status();
}

void DeviceCore::class_request(const SetupPacket& s) {
  if ((s.request_type & kRecipientMask) != kRecipientInterface || s.index != 0) {
    dcd_.ep0_stall();
    return;
  }
  switch (s.request) {
    case kSetIdle:
      idle_rate_ = static_cast<std::uint8_t>(s.value >> 8U);
      dcd_.ep0_status();
      return;
    case kGetIdle:
      ep0_buffer_[0] = idle_rate_;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(1), s.length);
      return;
    case kSetProtocol:
      protocol_ = static_cast<std::uint8_t>(s.value & 1U);
      dcd_.ep0_status();
      return;
    case kGetProtocol:
      ep0_buffer_[0] = protocol_;
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(1), s.length);
      return;
    case kGetReport: {
      // The last input report of that id (a host polling the control pipe);
      // id + zeros before the first. Other report types do not exist here.
      const auto id = static_cast<std::uint8_t>(s.value & 0xFFU);
      const int kind = id == proto::hid::kReportIdStream ? 0 : (id == proto::hid::kReportIdResponse ? 1 : -1);
      if ((s.value >> 8U) != kReportTypeInput || kind < 0) break;
      const LastInput& last = last_input_[static_cast<std::size_t>(kind)];
      ep0_buffer_.fill(0);
      ep0_buffer_[0] = id;
      if (last.any.load()) {
        const proto::hid::Report& r = last.slot[last.published.load()];
        std::copy(r.begin(), r.end(), ep0_buffer_.begin());
      }
      reply(std::span<const std::uint8_t>(ep0_buffer_).first(proto::hid::kReportSize), s.length);
      return;
    }
    case kSetReport:
      // An output report sent through the control pipe (hidraw without an OUT endpoint).
      if ((s.value >> 8U) != kReportTypeOutput || s.length == 0 || s.length > proto::hid::kReportSize ||
          (s.request_type & kDirIn) != 0) {
        break;
      }
      set_report_pending_ = true;
      dcd_.ep0_receive(s.length);
      return;
    default: break;
  }
  dcd_.ep0_stall();
}

void DeviceCore::on_ep0_data(std::span<const std::uint8_t> data) {
  if (!set_report_pending_) return;
  set_report_pending_ = false;
  queue_output(data);
  dcd_.ep0_status();
}

void DeviceCore::on_hid_out(std::span<const std::uint8_t> packet) { queue_output(packet); }

void DeviceCore::queue_output(std::span<const std::uint8_t> bytes) {
  const std::size_t head = out_head_.load(std::memory_order_relaxed);
  const std::size_t next = (head + 1) % kOutQueue;
  if (next == out_tail_.load(std::memory_order_acquire)) {
    ++out_overflows_;  // the main loop is not draining commands: drop the newest
    return;
  }
  OutReport& slot = out_[head];
  slot.bytes.fill(0);
  slot.length = bytes.size() < slot.bytes.size() ? bytes.size() : slot.bytes.size();
  for (std::size_t k = 0; k < slot.length; ++k) slot.bytes[k] = bytes[k];
  out_head_.store(next, std::memory_order_release);
}

bool DeviceCore::receive_output(proto::hid::Report& report, std::size_t& length) {
  const std::size_t tail = out_tail_.load(std::memory_order_relaxed);
  if (tail == out_head_.load(std::memory_order_acquire)) return false;
  report = out_[tail].bytes;
  length = out_[tail].length;
  out_tail_.store((tail + 1) % kOutQueue, std::memory_order_release);
  return true;
}

bool DeviceCore::send_input(const proto::hid::Report& report) {
  if (!connected()) return false;
  forget_old_session();
  if (report[0] == proto::hid::kReportIdStream) {
    if (stream_waiting_) ++stream_superseded_;  // the newest report carries the newest levels
    stream_ = report;
    stream_waiting_ = true;
  } else if (report[0] == proto::hid::kReportIdResponse) {
    if (response_count_ == kResponseQueue) return false;
    responses_[(response_head_ + response_count_) % kResponseQueue] = report;
    ++response_count_;
  } else {
    return false;
  }
  service();
  return true;
}

void DeviceCore::forget_old_session() {
  if (!drop_input_.exchange(false)) return;
  if (stream_waiting_) ++stream_superseded_;
  stream_waiting_ = false;
  response_count_ = 0;
}

void DeviceCore::service() {
  forget_old_session();
  if (!connected() || in_halted_.load()) return;
  const bool response_first = response_count_ != 0 && (last_was_stream_ || !stream_waiting_);
  if (response_first) {
    if (!load(responses_[response_head_])) return;
    response_head_ = (response_head_ + 1) % kResponseQueue;
    --response_count_;
    last_was_stream_ = false;
  } else if (stream_waiting_) {
    if (!load(stream_)) return;
    stream_waiting_ = false;
    last_was_stream_ = true;
  }
}

bool DeviceCore::idle() const { return !stream_waiting_ && response_count_ == 0 && !dcd_.hid_busy(); }

bool DeviceCore::load(const proto::hid::Report& report) {
  // The DCD refuses while the previous packet is still in flight (the host
  // polls EP1 once per 1 ms frame); it copies an accepted packet before returning.
  static_assert(proto::hid::kReportSize == kHidPacket);
  if (!dcd_.hid_send(report)) return false;
  const int kind = report[0] == proto::hid::kReportIdStream ? 0 : 1;
  LastInput& last = last_input_[static_cast<std::size_t>(kind)];
  const auto next = static_cast<std::uint8_t>(last.published.load() ^ 1U);
  last.slot[next] = report;
  last.published.store(next);
  last.any.store(true);
  return true;
}

}  // namespace tonus::usb
