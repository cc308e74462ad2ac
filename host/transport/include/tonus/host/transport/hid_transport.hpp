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

struct hid_device_;

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

class HidapiTransport final : public HidTransport {
 public:
  // Opens the first band with this VID/PID (and serial, if not empty), reads
  // its report descriptor and refuses a device that is not a tonus band.
  static std::unique_ptr<HidapiTransport> open(std::uint16_t vid, std::uint16_t pid, const std::wstring& serial,
                                               std::string& error);
  ~HidapiTransport() override;
  HidapiTransport(const HidapiTransport&) = delete;
  HidapiTransport& operator=(const HidapiTransport&) = delete;

  int read(std::span<std::uint8_t> out, int timeout_ms) override;
  bool write(std::span<const std::uint8_t> report) override;
  [[nodiscard]] std::string error() const override { return error_; }
  [[nodiscard]] const std::vector<std::uint8_t>& descriptor() const { return descriptor_; }

 private:
  HidapiTransport(hid_device_* dev, std::string path) : dev_(dev), path_(std::move(path)) {}
  hid_device_* dev_;
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
