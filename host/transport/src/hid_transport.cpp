#include "tonus/host/transport/hid_transport.hpp"

#include <hidapi.h>
#include <unistd.h>

#include <fstream>

#include "seqpacket.hpp"
#include "tonus/protocol/hid.hpp"

namespace tonus::host {

namespace {

std::string narrow(const wchar_t* w) {
  if (w == nullptr) return "unknown error";
  std::string s;
  for (; *w != L'\0'; ++w) s.push_back(*w < 128 ? static_cast<char>(*w) : '?');
  return s;
}

// hidapi 0.14 has hid_get_report_descriptor; Debian 12 ships 0.13, whose
// hidraw backend exposes the same bytes in sysfs beside the device node.
bool read_descriptor(hid_device* dev, const std::string& path, std::vector<std::uint8_t>& out) {
#if HID_API_VERSION >= HID_API_MAKE_VERSION(0, 14, 0)
  std::vector<std::uint8_t> buf(HID_API_MAX_REPORT_DESCRIPTOR_SIZE);
  const int n = hid_get_report_descriptor(dev, buf.data(), buf.size());
  if (n <= 0) return false;
  buf.resize(static_cast<std::size_t>(n));
  out = std::move(buf);
  return true;
#else
  (void)dev;
  const auto slash = path.rfind('/');
  const std::string node = slash == std::string::npos ? path : path.substr(slash + 1);
  std::ifstream in("/sys/class/hidraw/" + node + "/device/report_descriptor", std::ios::binary);
  if (!in) return false;
  std::vector<std::uint8_t> buf(HID_API_MAX_REPORT_DESCRIPTOR_SIZE);
  in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
  buf.resize(static_cast<std::size_t>(in.gcount()));
  out = std::move(buf);
  return !out.empty();
#endif
}

}  // namespace

std::string check_band_descriptor(std::span<const std::uint8_t> descriptor) {
  proto::hid::DescriptorInfo info{};
  if (proto::hid::parse_report_descriptor(descriptor, info) != proto::Error::ok) return "unparsable report descriptor";
  if (info.usage_page != proto::hid::kUsagePage) return "not a tonus band (usage page is not 0xFF00)";
  using proto::hid::ReportType;
  if (info.report_bytes(proto::hid::kReportIdStream, ReportType::input) != proto::hid::kReportSize ||
      info.report_bytes(proto::hid::kReportIdCommand, ReportType::output) != proto::hid::kReportSize ||
      info.report_bytes(proto::hid::kReportIdResponse, ReportType::input) != proto::hid::kReportSize) {
    return "report layout differs from the tonus protocol (64-byte reports 1, 2, 3)";
  }
  return {};
}

std::unique_ptr<HidapiTransport> HidapiTransport::open(std::uint16_t vid, std::uint16_t pid, const std::wstring& serial,
                                                       std::string& error) {
  if (hid_init() != 0) {
    error = "hid_init failed: " + narrow(hid_error(nullptr));
    return nullptr;
  }
  // Enumerate to learn the hidraw path (needed for the descriptor on hidapi < 0.14).
  std::string path;
  hid_device_info* list = hid_enumerate(vid, pid);
  for (hid_device_info* d = list; d != nullptr; d = d->next) {
    if (!serial.empty() && (d->serial_number == nullptr || serial != d->serial_number)) continue;
    path = d->path;
    break;
  }
  hid_free_enumeration(list);
  if (path.empty()) {
    error = "no tonus band with VID:PID " + std::to_string(vid) + ":" + std::to_string(pid) + " is plugged in";
    return nullptr;
  }
  hid_device* dev = hid_open_path(path.c_str());
  if (dev == nullptr) {
    error = "cannot open " + path + ": " + narrow(hid_error(nullptr)) + " (udev permissions?)";
    return nullptr;
  }
  std::unique_ptr<HidapiTransport> t(new HidapiTransport(dev, path));
  if (!read_descriptor(dev, path, t->descriptor_)) {
    error = "cannot read the report descriptor of " + path;
    return nullptr;
  }
  if (std::string why = check_band_descriptor(t->descriptor_); !why.empty()) {
    error = path + ": " + why;
    return nullptr;
  }
  return t;
}

HidapiTransport::~HidapiTransport() {
  if (dev_ != nullptr) hid_close(dev_);
}

int HidapiTransport::read(std::span<std::uint8_t> out, int timeout_ms) {
  const int n = hid_read_timeout(dev_, out.data(), out.size(), timeout_ms);
  if (n < 0) error_ = "hid_read_timeout: " + narrow(hid_error(dev_));
  return n;
}

bool HidapiTransport::write(std::span<const std::uint8_t> report) {
  if (hid_write(dev_, report.data(), report.size()) == static_cast<int>(report.size())) return true;
  error_ = "hid_write: " + narrow(hid_error(dev_));
  return false;
}

std::unique_ptr<SeqpacketHidTransport> SeqpacketHidTransport::connect(const std::string& path, std::string& error) {
  const int fd = detail::connect_seqpacket(path, error);
  if (fd < 0) return nullptr;
  return std::make_unique<SeqpacketHidTransport>(fd);
}

SeqpacketHidTransport::~SeqpacketHidTransport() {
  if (fd_ >= 0) ::close(fd_);
}

int SeqpacketHidTransport::read(std::span<std::uint8_t> out, int timeout_ms) {
  const long n = detail::receive_datagram(fd_, out, timeout_ms, error_);
  if (n > static_cast<long>(out.size())) {
    error_ = "oversized report (" + std::to_string(n) + " bytes)";
    return static_cast<int>(out.size()) + 1;  // the caller's decoder refuses it (bad_length)
  }
  return static_cast<int>(n);
}

bool SeqpacketHidTransport::write(std::span<const std::uint8_t> report) {
  return detail::send_datagram(fd_, report, error_);
}

}  // namespace tonus::host
