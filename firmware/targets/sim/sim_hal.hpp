// The HAL of tonus-band-sim: the band's core runs unchanged on Linux, with
//   - a sampler fed by a synthetic generator or a recording (double buffer,
//     scripted lost blocks),
//   - USB-HID as a Unix SOCK_SEQPACKET socket carrying exactly the 64-byte
//     reports hidraw/hidapi would carry,
//   - CAN as a SOCK_SEQPACKET socket carrying SocketCAN's struct can_frame
//     (optionally logged in candump format),
//   - a virtual clock (--fast: time is the sample clock) or the wall clock,
//   - flash-like storage in RAM, optionally backed by a file.
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "emg_recording.hpp"
#include "tonus/firmware/synthetic.hpp"
#include "tonus/hal/board.hpp"

namespace tonus::sim {

// Where the sampler's frames come from.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  [[nodiscard]] virtual fw::FrontEnd front_end() const = 0;
  [[nodiscard]] virtual float sample_rate_hz() const = 0;
  [[nodiscard]] virtual std::size_t total_frames() const = 0;
  // Fills up to `frames` frames; returns how many (0 at the end).
  virtual std::size_t generate(std::span<std::int16_t> out, std::size_t frames) = 0;
  // The sampler loses the block covering these frames (scripted fault).
  [[nodiscard]] virtual bool lose_block(std::size_t first, std::size_t count) const = 0;
};

std::unique_ptr<FrameSource> make_synthetic_source(const fw::SynthSpec& spec);
std::unique_ptr<FrameSource> make_recording_source(Recording rec);

class SimClock final : public hal::Clock {
 public:
  explicit SimClock(bool realtime) : realtime_(realtime), start_(std::chrono::steady_clock::now()) {}
  [[nodiscard]] std::uint64_t now_us() const override;
  void advance_to(std::uint64_t t_us) { virtual_us_ = t_us > virtual_us_ ? t_us : virtual_us_; }
  [[nodiscard]] bool realtime() const { return realtime_; }
  // Real time only: the device clock reads offset_us + h * (1 + drift_ppm * 1e-6)
  // at host steady time h (CLOCK_MONOTONIC, us), a truth a host's time sync can be checked against.
  void set_host_mapping(std::int64_t offset_us, double drift_ppm);
  // Device time of `elapsed_us` after start in real time (the sampler's stamps).
  [[nodiscard]] std::uint64_t from_elapsed_us(std::uint64_t elapsed_us) const;
  // A reboot: like the band's SysTick count, the device clock starts again from 0.
  void restart();
  // Wall-clock time for logs (candump): the Unix time at start plus the time
  // run since, unaffected by restarts, so a log's time base never jumps back.
  [[nodiscard]] std::uint64_t log_time_us() const;
  // Device time of a sampler stamp taken on the clock's running base (fast: virtual us,
  // real time: from_elapsed_us), after the last restart; stamps from before it give 0.
  [[nodiscard]] std::uint64_t since_restart(std::uint64_t base_us) const {
    return base_us > restart_base_us_ ? base_us - restart_base_us_ : 0;
  }

 private:
  bool realtime_;
  std::chrono::steady_clock::time_point start_;
  std::uint64_t unix_start_us_ = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
  std::uint64_t virtual_us_ = 0;
  bool mapped_ = false;
  std::uint64_t restart_base_us_ = 0;
  std::int64_t offset_us_ = 0;
  double drift_ppm_ = 0.0;
};

class SimSampler final : public hal::EmgSampler {
 public:
  SimSampler(FrameSource& source, SimClock& clock, std::size_t block_frames)
      : source_(source), clock_(clock), block_frames_(block_frames) {}
  [[nodiscard]] fw::FrontEnd front_end() const override { return source_.front_end(); }
  bool start(std::uint16_t rate_hz) override;
  const hal::SampleBlock* acquire() override;
  void release() override;

  // Completes the next block of the source (the DMA half-transfer); false at the end.
  bool produce();
  [[nodiscard]] std::uint64_t next_block_start_us() const;
  [[nodiscard]] std::size_t frames_done() const { return frames_done_; }
  [[nodiscard]] std::uint32_t dropped() const { return dropped_; }

 private:
  FrameSource& source_;
  SimClock& clock_;
  std::size_t block_frames_;
  bool running_ = false;
  std::array<hal::SampleBlock, 2> halves_{};
  std::array<bool, 2> ready_{};
  std::size_t write_half_ = 0;
  std::size_t read_half_ = 0;
  std::uint32_t sequence_ = 0;
  std::size_t frames_done_ = 0;
  std::uint32_t dropped_ = 0;
};

class FlashStorage final : public hal::Storage {
 public:
  static constexpr std::size_t kSectorSize = std::size_t{16} * 1024;  // STM32F405 sectors 1 and 2
  static constexpr std::size_t kSectors = 2;
  static constexpr std::size_t kSize = kSectorSize * kSectors;
  // A file written by an older simulator (one sector) is read into the first.
  explicit FlashStorage(std::string path = {});
  [[nodiscard]] std::size_t sector_size() const override { return kSectorSize; }
  [[nodiscard]] std::size_t sector_count() const override { return kSectors; }
  bool read(std::size_t offset, std::span<std::uint8_t> out) override;
  bool erase(std::size_t sector) override;
  bool program(std::size_t offset, std::span<const std::uint8_t> data) override;
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  void persist();
  std::string path_;
  std::vector<std::uint8_t> bytes_;
};

class SimLed final : public hal::StatusLed {
 public:
  void show(hal::LedPattern p) override { pattern_ = p; }
  [[nodiscard]] hal::LedPattern pattern() const { return pattern_; }

 private:
  hal::LedPattern pattern_ = hal::LedPattern::off;
};

class SimWatchdog final : public hal::Watchdog {
 public:
  void kick() override { ++kicks_; }
  [[nodiscard]] bool caused_last_reset() const override { return false; }
  [[nodiscard]] std::uint64_t kicks() const { return kicks_; }

 private:
  std::uint64_t kicks_ = 0;
};

class SimSystem final : public hal::SystemControl {
 public:
  SimSystem();  // a per-process boot epoch, never 0
  // retained: the band's boot count persists (a storage file), so the board
  // says 0 and the device's own boot count sets the epoch; a random per-process
  // epoch repeats the previous run's once in 255 runs.
  explicit SimSystem(bool retained) : SimSystem() {
    if (retained) epoch_ = 0;
  }
  void reset() override { requested_ = true; }
  // The reboot the band would do; the next boot gets the next epoch.
  bool take_reset() {
    const bool r = requested_;
    requested_ = false;
    if (r) {
      if (epoch_ != 0) epoch_ = static_cast<std::uint8_t>(epoch_ % 255U + 1U);
      cause_ = proto::ResetCause::software;
    }
    return r;
  }
  [[nodiscard]] std::uint8_t boot_epoch() const override { return epoch_; }
  [[nodiscard]] proto::ResetCause reset_cause() const override { return cause_; }
  // The simulated band "has" the DFU bootloader: entering it is counted and
  // comes straight back as a software reboot (no image is flashed here).
  [[nodiscard]] bool has_bootloader() const override { return true; }
  void enter_bootloader() override {
    ++bootloader_entries_;
    requested_ = true;
  }
  [[nodiscard]] int bootloader_entries() const { return bootloader_entries_; }

 private:
  bool requested_ = false;
  std::uint8_t epoch_ = 1;
  proto::ResetCause cause_ = proto::ResetCause::power_on;
  int bootloader_entries_ = 0;
};

// A SOCK_SEQPACKET endpoint: an inherited connected fd, or a listening socket
// path that accepts one host at a time. In fast mode sends block (the reader
// paces the simulation, nothing is dropped); in real time they never block.
class SeqpacketEndpoint {
 public:
  SeqpacketEndpoint() = default;
  ~SeqpacketEndpoint();
  SeqpacketEndpoint(const SeqpacketEndpoint&) = delete;
  SeqpacketEndpoint& operator=(const SeqpacketEndpoint&) = delete;

  bool adopt_fd(int fd, std::string& error);
  bool listen_on(const std::string& path, std::string& error);
  void set_blocking_send(bool b) { blocking_send_ = b; }

  [[nodiscard]] bool connected();
  bool send(std::span<const std::uint8_t> bytes);
  // Non-blocking; returns the datagram size, 0 if none.
  std::size_t receive(std::span<std::uint8_t> out);
  [[nodiscard]] bool peer_gone() const { return peer_gone_; }

 private:
  void drop_peer();
  int listen_fd_ = -1;
  int fd_ = -1;
  std::string path_;
  bool blocking_send_ = false;
  bool peer_gone_ = false;
};

class SeqpacketHid final : public hal::UsbHid {
 public:
  explicit SeqpacketHid(SeqpacketEndpoint& ep) : ep_(ep) {}
  [[nodiscard]] bool connected() const override { return ep_.connected(); }
  bool send_input(const proto::hid::Report& report) override { return ep_.send(report); }
  void service() override {}                                 // sends go straight to the socket
  [[nodiscard]] bool idle() const override { return true; }  // nothing is ever held back
  bool receive_output(proto::hid::Report& report, std::size_t& length) override;

 private:
  SeqpacketEndpoint& ep_;
};

class SeqpacketCan final : public hal::CanPort {
 public:
  SeqpacketCan(SeqpacketEndpoint& ep, const SimClock& clock, std::FILE* candump)
      : ep_(ep), clock_(clock), candump_(candump) {}
  bool send(const proto::CanFrame& frame) override;
  bool receive(proto::CanFrame& frame) override;
  [[nodiscard]] bool idle() const override { return true; }  // sends go straight to the socket
  [[nodiscard]] std::uint64_t frames_sent() const { return sent_; }

 private:
  void log(const proto::CanFrame& frame);
  SeqpacketEndpoint& ep_;
  const SimClock& clock_;
  std::FILE* candump_;
  std::uint64_t sent_ = 0;
};

// A CAN port with no bus attached: frames are only logged (candump), never lost.
class LogOnlyCan final : public hal::CanPort {
 public:
  LogOnlyCan(const SimClock& clock, std::FILE* candump) : clock_(clock), candump_(candump) {}
  bool send(const proto::CanFrame& frame) override;
  bool receive(proto::CanFrame&) override { return false; }
  [[nodiscard]] bool idle() const override { return true; }

 private:
  const SimClock& clock_;
  std::FILE* candump_;
};

}  // namespace tonus::sim
