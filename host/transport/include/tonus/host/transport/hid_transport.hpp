// Host side of the band's USB-HID link: 64-byte reports, report id first
// (tonus::proto::hid). Two implementations of one interface:
//   HidapiTransport    - the real device through hidapi (hidraw backend)
//   SeqpacketHidTransport - a Unix SOCK_SEQPACKET socket carrying exactly the
//                        same reports, to talk to tonus-band-sim
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tonus/protocol/hid_descriptor.hpp"

namespace tonus::host {

class HidTransport {
 public:
  virtual ~HidTransport() = default;
  // Reads one input report into `out` (>= 64 bytes). Returns its size, 0 on
  // timeout, -1 when the device is gone (see error()).
  virtual int read(std::span<std::uint8_t> out, int timeout_ms) = 0;
  // Writes one output report (id first). False when the device is gone.
  virtual bool write(std::span<const std::uint8_t> report) = 0;
  [[nodiscard]] virtual std::string error() const = 0;
};

// Checks that a report descriptor is the band's: vendor page 0xFF00 and
// 64-byte reports 1 (input), 2 (output), 3 (input). Empty string when it is.
std::string check_band_descriptor(std::span<const std::uint8_t> descriptor);

// The hidapi calls HidapiTransport makes, behind an interface so that a test
// can enumerate, unplug and replug fake devices (hidapi_backend() is the real one).
struct HidDeviceEntry {
  std::string path;
  std::wstring serial;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
};

class HidDevice {  // one open device (hid_device)
 public:
  virtual ~HidDevice() = default;
  virtual int read(std::span<std::uint8_t> out, int timeout_ms) = 0;  // hid_read_timeout
  virtual int write(std::span<const std::uint8_t> report) = 0;        // hid_write
  virtual bool report_descriptor(std::vector<std::uint8_t>& out) = 0;
  [[nodiscard]] virtual std::string error() const = 0;  // hid_error
};

class HidBackend {
 public:
  virtual ~HidBackend() = default;
  virtual bool init(std::string& error) = 0;                                                 // hid_init
  virtual std::vector<HidDeviceEntry> enumerate(std::uint16_t vid, std::uint16_t pid) = 0;   // hid_enumerate
  virtual std::unique_ptr<HidDevice> open(const std::string& path, std::string& error) = 0;  // hid_open_path
};

HidBackend& hidapi_backend();

class HidapiTransport final : public HidTransport {
 public:
  // Enumerates afresh (so a replugged band is found on its new node) and opens
  // the first band with this VID/PID (and serial, if not empty) that opens and
  // whose report descriptor is a tonus band's, trying every match in turn.
  // nullptr with `error` naming why each match was refused.
  static std::unique_ptr<HidapiTransport> open(std::uint16_t vid, std::uint16_t pid, const std::wstring& serial,
                                               std::string& error, HidBackend& backend = hidapi_backend());
  ~HidapiTransport() override = default;
  HidapiTransport(const HidapiTransport&) = delete;
  HidapiTransport& operator=(const HidapiTransport&) = delete;

  int read(std::span<std::uint8_t> out, int timeout_ms) override;
  bool write(std::span<const std::uint8_t> report) override;
  [[nodiscard]] std::string error() const override { return error_; }
  [[nodiscard]] const std::vector<std::uint8_t>& descriptor() const { return descriptor_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  HidapiTransport(std::unique_ptr<HidDevice> dev, std::string path, std::vector<std::uint8_t> descriptor)
      : dev_(std::move(dev)), path_(std::move(path)), descriptor_(std::move(descriptor)) {}
  std::unique_ptr<HidDevice> dev_;
  std::string path_;
  std::vector<std::uint8_t> descriptor_;
  std::string error_;
};

class SeqpacketHidTransport final : public HidTransport {
 public:
  // Takes ownership of a connected SOCK_SEQPACKET socket.
  explicit SeqpacketHidTransport(int fd) : fd_(fd) {}
  // Connects to tonus-band-sim --hid-socket PATH; nullptr and `error` on failure.
  static std::unique_ptr<SeqpacketHidTransport> connect(const std::string& path, std::string& error);
  ~SeqpacketHidTransport() override;
  SeqpacketHidTransport(const SeqpacketHidTransport&) = delete;
  SeqpacketHidTransport& operator=(const SeqpacketHidTransport&) = delete;

  int read(std::span<std::uint8_t> out, int timeout_ms) override;
  bool write(std::span<const std::uint8_t> report) override;
  [[nodiscard]] std::string error() const override { return error_; }

 private:
  int fd_;
  std::string error_;
};

}  // namespace tonus::host
