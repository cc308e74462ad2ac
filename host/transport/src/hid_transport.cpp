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

namespace {

class HidapiDevice final : public HidDevice {
 public:
  HidapiDevice(hid_device* dev, std::string path) : dev_(dev), path_(std::move(path)) {}
  ~HidapiDevice() override { hid_close(dev_); }
  HidapiDevice(const HidapiDevice&) = delete;
  HidapiDevice& operator=(const HidapiDevice&) = delete;
  int read(std::span<std::uint8_t> out, int timeout_ms) override {
    return hid_read_timeout(dev_, out.data(), out.size(), timeout_ms);
  }
  int write(std::span<const std::uint8_t> report) override { return hid_write(dev_, report.data(), report.size()); }
  bool report_descriptor(std::vector<std::uint8_t>& out) override { return read_descriptor(dev_, path_, out); }
  [[nodiscard]] std::string error() const override { return narrow(hid_error(dev_)); }

 private:
  hid_device* dev_;
  std::string path_;
};

class Hidapi final : public HidBackend {
 public:
  bool init(std::string& error) override {
    if (hid_init() == 0) return true;
    error = "hid_init failed: " + narrow(hid_error(nullptr));
    return false;
  }
  std::vector<HidDeviceEntry> enumerate(std::uint16_t vid, std::uint16_t pid) override {
    std::vector<HidDeviceEntry> out;
    hid_device_info* list = hid_enumerate(vid, pid);
    for (const hid_device_info* d = list; d != nullptr; d = d->next) {
      HidDeviceEntry e;
      e.path = d->path != nullptr ? d->path : "";
      e.serial = d->serial_number != nullptr ? d->serial_number : L"";
      e.vendor_id = d->vendor_id;
      e.product_id = d->product_id;
      out.push_back(std::move(e));
    }
    hid_free_enumeration(list);
    return out;
  }
  std::unique_ptr<HidDevice> open(const std::string& path, std::string& error) override {
    hid_device* dev = hid_open_path(path.c_str());
    if (dev == nullptr) {
      error = narrow(hid_error(nullptr)) + " (udev permissions? see packaging/udev)";
      return nullptr;
    }
    return std::make_unique<HidapiDevice>(dev, path);
  }
};

std::string hex4(std::uint16_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s(4, '0');
  for (int k = 3; k >= 0; --k, v = static_cast<std::uint16_t>(v >> 4U))
    s[static_cast<std::size_t>(k)] = kDigits[v & 0xFU];
  return s;
}

}  // namespace

HidBackend& hidapi_backend() {
  static Hidapi backend;
  return backend;
}

std::unique_ptr<HidapiTransport> HidapiTransport::open(std::uint16_t vid, std::uint16_t pid, const std::wstring& serial,
                                                       std::string& error, HidBackend& backend) {
  if (!backend.init(error)) return nullptr;
  std::string refused;
  for (const HidDeviceEntry& d : backend.enumerate(vid, pid)) {
    // hid_enumerate(0, 0) lists everything: keep to the ids asked for.
    if ((vid != 0 && d.vendor_id != vid) || (pid != 0 && d.product_id != pid)) continue;
    if (!serial.empty() && d.serial != serial) continue;
    std::string why;
    std::unique_ptr<HidDevice> dev = backend.open(d.path, why);
    std::vector<std::uint8_t> descriptor;
    if (dev == nullptr) {
      why.insert(0, "cannot open: ");
    } else if (!dev->report_descriptor(descriptor)) {
      why = "cannot read the report descriptor";
    } else {
      why = check_band_descriptor(descriptor);
    }
    if (why.empty()) return std::unique_ptr<HidapiTransport>(new HidapiTransport(std::move(dev), d.path, descriptor));
    refused += (refused.empty() ? "" : "; ") + d.path + ": " + why;
  }
  error = refused.empty() ? "no tonus band with VID:PID " + hex4(vid) + ":" + hex4(pid) + " is plugged in" : refused;
  return nullptr;
}

int HidapiTransport::read(std::span<std::uint8_t> out, int timeout_ms) {
  const int n = dev_->read(out, timeout_ms);
  if (n < 0) error_ = "hid_read_timeout: " + dev_->error();
  return n;
}

bool HidapiTransport::write(std::span<const std::uint8_t> report) {
  if (dev_->write(report) == static_cast<int>(report.size())) return true;
  error_ = "hid_write: " + dev_->error();
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
