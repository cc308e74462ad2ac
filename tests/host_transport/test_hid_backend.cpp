// The hidapi path through its seam (HidBackend): every matching band is tried,
// and a band unplugged and replugged on another node is found again.
#include <doctest/doctest.h>

#include <map>

#include "fake_transports.hpp"
#include "tonus/host/transport/reconnecting_link.hpp"

using namespace tonus;
using namespace std::chrono_literals;

namespace {

const std::vector<std::uint8_t> kBand(proto::hid::kReportDescriptor.begin(), proto::hid::kReportDescriptor.end());
const std::vector<std::uint8_t> kMouse = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0xC0};

// A plugged device: its descriptor, whether it opens, and the reports it will give.
struct FakeDeviceSpec {
  std::uint16_t vid = 0x1209, pid = 0x0001;
  std::vector<std::uint8_t> descriptor = kBand;
  bool opens = true;
  std::shared_ptr<test::FakeHidTransport> reports = std::make_shared<test::FakeHidTransport>();
};

class FakeDevice final : public host::HidDevice {
 public:
  explicit FakeDevice(FakeDeviceSpec spec) : spec_(std::move(spec)) {}
  int read(std::span<std::uint8_t> out, int timeout_ms) override { return spec_.reports->read(out, timeout_ms); }
  int write(std::span<const std::uint8_t> r) override {
    return spec_.reports->write(r) ? static_cast<int>(r.size()) : -1;
  }
  bool report_descriptor(std::vector<std::uint8_t>& out) override {
    out = spec_.descriptor;
    return !out.empty();
  }
  [[nodiscard]] std::string error() const override { return "device unplugged"; }

 private:
  FakeDeviceSpec spec_;
};

class FakeBackend final : public host::HidBackend {
 public:
  std::map<std::string, FakeDeviceSpec> plugged;  // by hidraw path
  std::vector<std::string> opened;                // every open attempt, in order
  int enumerations = 0;

  bool init(std::string&) override { return true; }
  std::vector<host::HidDeviceEntry> enumerate(std::uint16_t vid, std::uint16_t pid) override {
    ++enumerations;
    std::vector<host::HidDeviceEntry> out;
    for (const auto& [path, d] : plugged) {
      if (d.vid == vid && d.pid == pid) out.push_back({path, L"", d.vid, d.pid});
    }
    return out;
  }
  std::unique_ptr<host::HidDevice> open(const std::string& path, std::string& error) override {
    opened.push_back(path);
    const auto it = plugged.find(path);
    if (it == plugged.end() || !it->second.opens) {
      error = "Permission denied";
      return nullptr;
    }
    return std::make_unique<FakeDevice>(it->second);
  }
};

}  // namespace

TEST_CASE("hidapi: every matching VID:PID is tried until one is a band") {
  FakeBackend backend;
  backend.plugged["/dev/hidraw0"].opens = false;        // no permission
  backend.plugged["/dev/hidraw1"].descriptor = kMouse;  // same ids, not a band
  backend.plugged["/dev/hidraw2"].descriptor = kBand;   // the band
  backend.plugged["/dev/hidraw3"].pid = 0x0002;         // another product: never opened
  std::string error;
  auto t = host::HidapiTransport::open(0x1209, 0x0001, L"", error, backend);
  REQUIRE_MESSAGE(t != nullptr, error);
  CHECK(t->path() == "/dev/hidraw2");
  CHECK(backend.opened == std::vector<std::string>{"/dev/hidraw0", "/dev/hidraw1", "/dev/hidraw2"});

  // None fits: the error names why each was refused.
  backend.plugged.erase("/dev/hidraw2");
  t = host::HidapiTransport::open(0x1209, 0x0001, L"", error, backend);
  CHECK(t == nullptr);
  CHECK(error.find("/dev/hidraw0: cannot open") != std::string::npos);
  CHECK(error.find("/dev/hidraw1: not a tonus band") != std::string::npos);
  backend.plugged.clear();
  t = host::HidapiTransport::open(0x1209, 0x0001, L"", error, backend);
  CHECK(t == nullptr);
  CHECK(error.find("1209:0001") != std::string::npos);
}

TEST_CASE("hidapi: unplugged and replugged on another node, the link re-enumerates and resumes") {
  FakeBackend backend;
  FakeDeviceSpec first;
  for (std::uint16_t i = 0; i < 300; ++i) first.reports->push(test::report(i, 40));
  backend.plugged["/dev/hidraw4"] = first;
  host::ReconnectPolicy policy;
  policy.first_retry = 5ms;
  policy.max_retry = 20ms;
  host::ReconnectingBandLink link(host::hidapi_opener(0x1209, 0x0001, L"", backend), policy);

  std::uint64_t fresh = 0, disconnects = 0, reconnects = 0;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  bool replugged = false;
  while (fresh < 600 && std::chrono::steady_clock::now() < deadline) {
    const host::LinkEvent e = link.poll(50);
    if (e.kind == host::LinkEvent::Kind::stream) ++fresh;
    if (e.kind == host::LinkEvent::Kind::reconnected) ++reconnects;
    if (e.kind == host::LinkEvent::Kind::disconnected) {
      ++disconnects;
      backend.plugged.clear();  // unplugged: the next enumerations find nothing
    }
    if (disconnects == 1 && !replugged && backend.enumerations >= 3) {
      // Replugged (after a reboot) on a new node.
      FakeDeviceSpec second;
      for (std::uint16_t i = 0; i < 300; ++i) second.reports->push(test::report(i, 41));
      second.reports->gone_when_empty = false;
      backend.plugged["/dev/hidraw7"] = second;
      replugged = true;
    }
  }
  CHECK(fresh == 600);
  CHECK(disconnects == 1);
  CHECK(reconnects == 2);  // the first open, and the one after the replug
  CHECK(backend.opened.back() == "/dev/hidraw7");
  CHECK(link.open_failures() >= 2);  // the enumerations that found nothing
  const host::LinkStats s = link.stats();
  CHECK(s.reconnects == 1);
  CHECK(s.disconnects == 1);
  CHECK(s.restarts == 1);
  CHECK(s.lost + s.stale + s.duplicates == 0);
}
