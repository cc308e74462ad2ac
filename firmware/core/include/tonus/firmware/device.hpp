// The band: sample blocks in, stiffness stream and command responses out.
//
// Device owns every piece of mutable state (preallocated, no heap) and talks
// to the chip only through the HAL in hal::Board. The main loop of a target
// calls boot() once after reset and then poll() forever; poll() never blocks:
// it answers pending commands, processes every completed sample block,
// streams a report each time the report clock ticks, sends the CAN heartbeat
// and kicks the watchdog.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "tonus/firmware/calibration.hpp"
#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/fault_log.hpp"
#include "tonus/firmware/levels.hpp"
#include "tonus/firmware/nv_record.hpp"
#include "tonus/firmware/quality.hpp"
#include "tonus/hal/board.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::fw {

inline constexpr std::uint32_t kHeartbeatPeriodUs = 1000000;
// A sampler that delivers no block for this long has stalled: it is restarted
// once; if that does not bring blocks back the band reports a fault and stops
// kicking the watchdog, so the chip resets.
inline constexpr std::uint64_t kSamplerStallUs = 200000;
// The longest a reset waits for its own answer to leave (HID: the host's next
// 1 ms poll; CAN: 64 queued frames take about 8 ms at 1 Mbit/s).
inline constexpr std::uint64_t kResetDrainUs = 50000;

// Which transport a command came in on; its response goes back the same way.
enum class Link : std::uint8_t { hid, can };

// Device-level configuration rules on top of proto::check_config: the sample
// rate must be one the sampler runs at, and only existing pairs may feed a group.
proto::ConfigField check_device_config(const proto::DeviceConfig& cfg, const FrontEnd& fe);

// Defaults adapted to a front end: its highest supported rate up to 2 kHz,
// and the low-pass dropped (0) when 450 Hz is not below Nyquist.
proto::DeviceConfig default_config(const FrontEnd& fe);

class Device {
 public:
  explicit Device(hal::Board& board) : board_(board) {}

  void boot();
  void poll();

  // Optional hook called with every report built (simulator summaries, tests).
  using ReportObserver = void (*)(void* context, const proto::StreamMessage& report);
  void set_report_observer(ReportObserver fn, void* context) {
    observer_ = fn;
    observer_context_ = context;
  }

  // Command handling, transport-independent (also used by tests directly).
  void handle(const proto::Request& req, std::uint64_t rx_us, proto::Response& rsp);

  // Observers for targets and tests.
  [[nodiscard]] const proto::DeviceConfig& config() const { return config_; }
  [[nodiscard]] const Calibration& calibration() const { return calibration_; }
  [[nodiscard]] const ChainModel& chain() const { return chain_; }
  [[nodiscard]] proto::DeviceStats stats() const;
  [[nodiscard]] std::uint16_t status_bits() const;
  [[nodiscard]] const proto::StreamMessage& last_report() const { return report_; }
  [[nodiscard]] std::uint32_t reports() const { return stats_.reports_sent; }
  [[nodiscard]] LoadResult boot_load_result() const { return load_result_; }
  [[nodiscard]] std::span<const float, kChannels> envelopes() const { return envelopes_; }
  [[nodiscard]] std::uint32_t stale_blocks() const { return stale_blocks_; }
  // The sampler delivered nothing for kSamplerStallUs even after a restart.
  [[nodiscard]] bool sampler_stalled() const { return sampler_stalled_; }
  [[nodiscard]] const Calibrator& calibrator() const { return calibrator_; }
  [[nodiscard]] std::uint32_t boot_count() const { return boot_count_; }
  [[nodiscard]] const FaultLog& fault_log() const { return faults_; }

 private:
  void apply_config(const proto::DeviceConfig& cfg, bool restart_sampler);
  void process_block(const hal::SampleBlock& block, std::uint64_t now_us);
  void check_sampler(std::uint64_t now_us);
  void process_frame(const std::int16_t* frame, std::uint64_t t_us);
  void emit_report(std::uint64_t t_us);
  void poll_hid();
  void poll_can();
  void receive(std::span<const std::uint8_t> message, Link link, std::uint64_t rx_us);
  // Sends a response; over CAN from `can_node`.
  void reply(const proto::Response& rsp, Link link, std::uint8_t can_node, std::uint32_t can_id_base);
  void after_reply(Link link);
  void reboot_when_drained(std::uint64_t now_us);
  void fault(proto::FaultCode code, std::uint16_t arg);
  [[nodiscard]] std::uint8_t boot_epoch() const;
  void send_heartbeat(std::uint64_t now_us);
  void update_led();

  void on_set_config(const proto::Request& req, proto::Response& rsp);
  void on_calibration_start(const proto::Request& req, proto::Response& rsp, std::uint64_t now_us);

  hal::Board& board_;
  FrontEnd front_end_{};
  proto::DeviceConfig config_{};
  Calibration calibration_{};
  ChainModel chain_{};
  QualityModel quality_model_{};
  LevelModel level_model_{};
  std::array<ChannelState, kChannels> channels_{};
  std::array<QualityState, kChannels> quality_{};
  LevelState level_state_{};
  Calibrator calibrator_{};
  std::array<float, kChannels> envelopes_{};
  std::array<float, kPairs> cocontraction_{};

  proto::StreamMessage report_{};
  proto::DeviceStats stats_{};
  std::uint64_t boot_us_ = 0;
  std::uint16_t sequence_ = 0;
  std::uint32_t report_phase_ = 0;  // Bresenham accumulator of the report clock
  std::uint32_t next_block_ = 0;
  bool block_seen_ = false;
  bool block_lost_pending_ = false;
  std::uint32_t stale_blocks_ = 0;
  bool config_dirty_ = false;
  bool watchdog_reset_ = false;
  bool sampler_ok_ = false;
  bool sampler_stalled_ = false;        // no blocks even after a restart
  std::uint64_t sampler_since_us_ = 0;  // the last block, or the last (re)start of the sampler
  std::uint8_t stall_restarts_ = 0;     // restarts since the last block
  LoadResult load_result_ = LoadResult::empty;
  std::uint64_t next_heartbeat_us_ = 0;
  proto::can::Reassembler can_requests_{proto::can::Function::request, 1};
  bool reset_pending_ = false;           // a `reset` was answered: reboot once the answer has left
  bool reset_issued_ = false;            // SystemControl::reset() called (the sim returns from it)
  std::uint64_t reset_deadline_us_ = 0;  // reboot anyway after this (a host that stopped polling)
  bool to_bootloader_ = false;           // the pending reboot goes to the update bootloader
  std::uint32_t boot_count_ = 0;         // 0: unknown (the storage holds no record of ours)
  proto::ResetCause reset_cause_ = proto::ResetCause::unknown;
  FaultLog faults_{};
  ReportObserver observer_ = nullptr;
  void* observer_context_ = nullptr;
  proto::ResetKind reset_kind_ = proto::ResetKind::reboot;
};

}  // namespace tonus::fw
