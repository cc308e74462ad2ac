// tonus-band-sim: the band's firmware core on Linux, the hardware-in-loop stub
// for tests and for the host daemon. See firmware/README.md.
#include <fmt/core.h>
#include <fmt/os.h>
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include "emg_recording.hpp"
#include "sim_hal.hpp"
#include "summary.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/protocol/sequence.hpp"

namespace {

using namespace tonus;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Options {
  std::string synthetic;
  std::string recording;
  double seconds = 0.0;
  std::uint64_t seed = 1;
  unsigned sample_rate_hz = 2000;
  unsigned mains_hz = 50;
  float step_from = 0.0F, step_to = 0.5F;
  float swell_period_s = 10.0F, swell_peak = 0.8F;
  bool fast = false;
  std::string json;
  std::string candump;
  std::string hid_socket, can_socket;
  int hid_fd = -1, can_fd = -1;
  std::string storage;
  bool quiet = false;
  std::int64_t clock_offset_us = 0;  // real time: device clock = offset + host steady us * (1 + ppm 1e-6)
  double clock_drift_ppm = 0.0;
  bool clock_mapped = false;
};

struct Observer {
  sim::Summary summary;
  proto::TimestampUnwrapper clock;
  static void on_report(void* self, const proto::StreamMessage& m) {
    auto* o = static_cast<Observer*>(self);
    o->summary.add(m, static_cast<std::uint64_t>(o->clock.push(m.device_time_us)));
  }
};

void write_json(const std::string& path, const Options& opt, const std::string& source, double seconds,
                const fw::Device& dev, const sim::Summary& s, const fw::ChainDelay& delay,
                const sim::StepLatency* step) {
  auto out = fmt::output_file(path);
  const proto::DeviceStats st = dev.stats();
  const auto list = [](auto values) {
    std::string r = "[";
    for (std::size_t k = 0; k < values.size(); ++k) r += (k ? ", " : "") + fmt::format("{}", values[k]);
    return r + "]";
  };
  const auto channels = [](std::uint16_t mask) {
    std::string r = "[";
    bool first = true;
    for (unsigned ch = 0; ch < fw::kChannels; ++ch) {
      if ((static_cast<unsigned>(mask) >> ch) & 1U) {
        r += fmt::format("{}{}", first ? "" : ", ", ch);
        first = false;
      }
    }
    return r + "]";
  };
  std::array<double, fw::kGroups> mean{};
  for (std::size_t g = 0; g < fw::kGroups; ++g) {
    mean[g] = s.reports ? s.levels_sum[g] / static_cast<double>(s.reports) : 0.0;
  }
  const std::array<std::uint16_t, fw::kGroups> no_reports{};
  out.print("{{\n");
  out.print("  \"source\": \"{}\",\n  \"seed\": {},\n  \"seconds\": {:.3f},\n", source, opt.seed, seconds);
  out.print("  \"sample_rate_hz\": {},\n  \"report_rate_hz\": {},\n", dev.config().sample_rate_hz,
            dev.config().report_rate_hz);
  out.print("  \"reports\": {},\n  \"sequence_continuous\": {},\n", s.reports, s.sequence_continuous);
  out.print("  \"lost_blocks\": {},\n  \"late_blocks\": {},\n  \"stale_blocks\": {},\n  \"tx_dropped\": {},\n",
            st.lost_blocks, st.late_blocks, dev.stale_blocks(), st.tx_dropped);
  out.print("  \"levels_min\": {},\n  \"levels_max\": {},\n", list(s.reports ? s.levels_min : no_reports),
            list(s.levels_max));
  out.print("  \"levels_mean\": {},\n", list(mean));
  out.print("  \"flags_seen\": {{\"electrode_off\": {}, \"saturation\": {}, \"artifact\": {}, \"block_lost\": {}}},\n",
            channels(s.electrode_off), channels(s.saturation), channels(s.artifact), s.block_lost_reports > 0);
  out.print(
      "  \"first_flag_s\": {{\"electrode_off\": {}, \"saturation\": {}, \"artifact\": {}, \"block_lost\": {:.4f}}},\n",
      list(s.first_off_s), list(s.first_saturation_s), list(s.first_artifact_s), s.first_block_lost_s);
  out.print("  \"status_seen\": {},\n", s.status_seen);
  out.print("  \"group_delay_ms\": {{\"filters\": {:.3f}, \"envelope\": {:.3f}, \"total\": {:.3f}}},\n",
            delay.filters_s * 1e3, delay.envelope_s * 1e3, delay.total_s() * 1e3);
  // Step to level, device time, measured on the level stream (--synthetic step only; null otherwise).
  const auto ms = [&](double v) { return step == nullptr || v < 0.0 ? std::string("null") : fmt::format("{:.1f}", v); };
  out.print("  \"level_latency_10_ms\": {},\n  \"level_latency_50_ms\": {},\n  \"level_latency_90_ms\": {}\n",
            ms(step ? step->ms10 : -1.0), ms(step ? step->ms50 : -1.0), ms(step ? step->ms90 : -1.0));
  out.print("}}\n");
}

int run(const Options& opt) {
  std::unique_ptr<sim::FrameSource> source;
  std::string source_name;
  std::optional<std::size_t> step_frame;  // --synthetic step: the frame the effort changes at
  if (!opt.recording.empty()) {
    sim::Recording rec;
    std::string error;
    if (!sim::load_recording(opt.recording, rec, error)) {
      fmt::print(stderr, "tonus-band-sim: {}\n", error);
      return 2;
    }
    if (opt.seconds > 0.0) {
      const auto n = static_cast<std::size_t>(opt.seconds * static_cast<double>(rec.sample_rate_hz));
      if (n < rec.frames.size()) rec.frames.resize(n);
    }
    source_name = fmt::format("recording {} ({}, {} Hz)", opt.recording, rec.format, rec.sample_rate_hz);
    source = sim::make_recording_source(std::move(rec));
  } else {
    fw::SynthSpec spec;
    if (!fw::parse_scenario(opt.synthetic.c_str(), spec.scenario)) {
      fmt::print(
          stderr,
          "tonus-band-sim: unknown scenario '{}' (rest, ramp, faults, bursts, hum, dropout, selftest, step, swell)\n",
          opt.synthetic);
      return 2;
    }
    spec.seed = opt.seed;
    spec.sample_rate_hz = static_cast<float>(opt.sample_rate_hz);
    spec.seconds = static_cast<float>(opt.seconds);
    spec.mains_hz = static_cast<float>(opt.mains_hz);
    spec.step_from = opt.step_from;
    spec.step_activation = opt.step_to;
    spec.swell_period_s = opt.swell_period_s;
    spec.swell_peak = opt.swell_peak;
    source_name = fmt::format("synthetic {}", opt.synthetic);
    if (spec.scenario == fw::Scenario::step) step_frame = fw::step_frame(spec);
    source = sim::make_synthetic_source(spec);
  }

  std::FILE* candump = nullptr;
  if (!opt.candump.empty()) {
    candump = std::fopen(opt.candump.c_str(), "w");
    if (candump == nullptr) {
      fmt::print(stderr, "tonus-band-sim: cannot write {}\n", opt.candump);
      return 2;
    }
  }

  sim::SimClock clock(!opt.fast);
  if (opt.clock_mapped) clock.set_host_mapping(opt.clock_offset_us, opt.clock_drift_ppm);
  // 1 ms blocks as on the band (2 frames at 2 kHz), at least one frame.
  const auto block_frames = std::max<std::size_t>(1, static_cast<std::size_t>(source->sample_rate_hz() / 1000.0F));
  sim::SimSampler sampler(*source, clock, block_frames);
  sim::FlashStorage storage(opt.storage);
  sim::SimLed led;
  sim::SimWatchdog watchdog;
  sim::SimSystem system(!opt.storage.empty());  // with storage, epochs follow the persisted boot count

  sim::SeqpacketEndpoint hid_ep, can_ep;
  std::unique_ptr<sim::SeqpacketHid> hid;
  std::unique_ptr<sim::SeqpacketCan> seam_can;
  std::unique_ptr<sim::LogOnlyCan> log_can;
  hal::CanPort* can = nullptr;
  std::string error;
  if (opt.hid_fd >= 0 || !opt.hid_socket.empty()) {
    const bool ok = opt.hid_fd >= 0 ? hid_ep.adopt_fd(opt.hid_fd, error) : hid_ep.listen_on(opt.hid_socket, error);
    if (!ok) {
      fmt::print(stderr, "tonus-band-sim: HID link: {}\n", error);
      return 2;
    }
    hid_ep.set_blocking_send(opt.fast);
    hid = std::make_unique<sim::SeqpacketHid>(hid_ep);
  }
  if (opt.can_fd >= 0 || !opt.can_socket.empty()) {
    const bool ok = opt.can_fd >= 0 ? can_ep.adopt_fd(opt.can_fd, error) : can_ep.listen_on(opt.can_socket, error);
    if (!ok) {
      fmt::print(stderr, "tonus-band-sim: CAN link: {}\n", error);
      return 2;
    }
    can_ep.set_blocking_send(opt.fast);
    seam_can = std::make_unique<sim::SeqpacketCan>(can_ep, clock, candump);
    can = seam_can.get();
  } else if (candump != nullptr) {
    log_can = std::make_unique<sim::LogOnlyCan>(clock, candump);
    can = log_can.get();
  }

  hal::Board board{sampler, clock, storage, led, watchdog, system, hid.get(), can, 0x7090000000000001ULL, 1};
  static fw::Device device(board);  // static: ~10 KiB of state, as on the band
  Observer observer;
  observer.summary.keep_levels = step_frame.has_value();
  device.set_report_observer(&Observer::on_report, &observer);
  device.boot();
  if (device.boot_load_result() != fw::LoadResult::loaded && !opt.storage.empty() && !opt.quiet) {
    fmt::print(stderr, "tonus-band-sim: storage {}: {}, using defaults\n", opt.storage,
               fw::to_string(device.boot_load_result()));
  }
  if (device.config().sample_rate_hz != static_cast<std::uint16_t>(source->sample_rate_hz())) {
    fmt::print(stderr, "tonus-band-sim: the stored configuration asks for {} Hz, the source runs at {} Hz\n",
               device.config().sample_rate_hz, source->sample_rate_hz());
  }

  const auto wall_start = std::chrono::steady_clock::now();
  bool more = true;
  while (more && g_stop == 0) {
    if (!opt.fast) std::this_thread::sleep_until(wall_start + std::chrono::microseconds(sampler.next_block_start_us()));
    more = sampler.produce();
    device.poll();
    if (system.take_reset()) {  // what the band does after NVIC_SystemReset: its clock restarts too
      clock.restart();
      device.boot();
    }
    // A host that connected over an inherited fd and went away ends the run.
    if ((opt.hid_fd >= 0 && hid_ep.peer_gone()) || (opt.can_fd >= 0 && can_ep.peer_gone())) {
      if (!opt.quiet) fmt::print(stderr, "tonus-band-sim: host closed the link, stopping\n");
      break;
    }
  }
  device.poll();  // answer commands that came with the last block
  if (candump != nullptr) std::fclose(candump);

  const double seconds = static_cast<double>(sampler.frames_done()) / static_cast<double>(source->sample_rate_hz());
  const sim::Summary& s = observer.summary;
  const fw::ChainDelay delay = fw::chain_group_delay(device.chain());
  const proto::DeviceStats st = device.stats();
  if (!opt.quiet) {
    fmt::print("tonus-band-sim: {}, {:.2f} s at {} Hz, reports at {} Hz\n", source_name, seconds,
               device.config().sample_rate_hz, device.config().report_rate_hz);
    fmt::print("  reports {}  lost blocks {}  late blocks {}  tx dropped {}  sequence {}\n", s.reports, st.lost_blocks,
               st.late_blocks, st.tx_dropped, s.sequence_continuous ? "continuous" : "GAPS");
    for (std::size_t g = 0; g < fw::kGroups; ++g) {
      fmt::print("  group {}: level min {:5}  max {:5}  mean {:8.1f}\n", g, s.reports ? s.levels_min[g] : 0,
                 s.levels_max[g], s.reports ? s.levels_sum[g] / static_cast<double>(s.reports) : 0.0);
    }
    fmt::print("  flags: electrode_off [{}]  saturation [{}]  artifact [{}]  block_lost {}\n",
               sim::channel_list(s.electrode_off), sim::channel_list(s.saturation), sim::channel_list(s.artifact),
               s.block_lost_reports > 0 ? "yes" : "no");
    fmt::print("  chain group delay: filters {:.2f} ms at {:.0f} Hz + envelope {:.2f} ms = {:.2f} ms\n",
               delay.filters_s * 1e3, fw::kReferenceEmgHz, delay.envelope_s * 1e3, delay.total_s() * 1e3);
  }
  std::optional<sim::StepLatency> step;
  if (step_frame && !s.level_time_us.empty()) {
    const std::uint64_t step_us = sim::frame_time_us(s.level_time_us.front(), *step_frame,
                                                     device.config().sample_rate_hz, device.config().report_rate_hz);
    step = sim::step_latency(s.level_time_us, s.levels, step_us);
    if (!opt.quiet) {
      fmt::print("  step to level (device time): 10 % {:.1f} ms  50 % {:.1f} ms  90 % {:.1f} ms ({} groups)\n",
                 step->ms10, step->ms50, step->ms90, step->groups);
    }
  }
  if (!opt.json.empty()) write_json(opt.json, opt, source_name, seconds, device, s, delay, step ? &*step : nullptr);
  return 0;
}

int cli_main(int argc, char** argv) {
  CLI::App app{"tonus-band-sim: the band firmware core on Linux (synthetic EMG or a recording)"};
  Options opt;
  auto* synth = app.add_option("--synthetic", opt.synthetic,
                               "scenario: rest, ramp, faults, bursts, hum, dropout, selftest, step, swell");
  auto* rec =
      app.add_option("--recording", opt.recording, "EMG recording (BioSPPy text or Myo CSV)")->check(CLI::ExistingFile);
  synth->excludes(rec);
  app.add_option("--seconds", opt.seconds, "duration (synthetic) or maximum length (recording)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--seed", opt.seed, "seed of the synthetic generator");
  app.add_option("--sample-rate", opt.sample_rate_hz, "synthetic sample rate, Hz")->check(CLI::Range(100, 4000));
  app.add_option("--mains", opt.mains_hz, "synthetic mains frequency, Hz")->check(CLI::IsMember({50, 60}));
  app.add_option("--step-from", opt.step_from, "step: the effort before the step (0 rest .. 1 MVC)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--step-to", opt.step_to, "step: the effort after the step (0 rest .. 1 MVC)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--swell-period", opt.swell_period_s, "swell: seconds of one rise and fall")
      ->check(CLI::Range(0.1, 1e6));
  app.add_option("--swell-peak", opt.swell_peak, "swell: the effort at the top (0 rest .. 1 MVC)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--fast", opt.fast, "run as fast as possible (virtual clock) instead of real time");
  app.add_option("--json", opt.json, "write a JSON summary to FILE");
  app.add_option("--candump", opt.candump, "log every CAN frame in candump -l format to FILE");
  app.add_option("--hid-socket", opt.hid_socket, "serve the HID link on a SOCK_SEQPACKET socket at PATH");
  app.add_option("--hid-fd", opt.hid_fd, "serve the HID link on an inherited connected SOCK_SEQPACKET fd");
  app.add_option("--can-socket", opt.can_socket, "serve the CAN link on a SOCK_SEQPACKET socket at PATH");
  app.add_option("--can-fd", opt.can_fd, "serve the CAN link on an inherited connected SOCK_SEQPACKET fd");
  app.add_option("--storage", opt.storage, "file backing the simulated flash (config and calibration)");
  app.add_flag("--quiet", opt.quiet, "no summary on stdout");
  // A known device clock, so a host's time sync can be checked against the truth.
  auto* offset = app.add_option("--clock-offset-us", opt.clock_offset_us,
                                "real time: device clock = OFFSET + host CLOCK_MONOTONIC us * (1 + drift)");
  auto* drift = app.add_option("--clock-drift-ppm", opt.clock_drift_ppm, "real time: device clock drift, ppm")
                    ->check(CLI::Range(-1000.0, 1000.0));
  CLI11_PARSE(app, argc, argv);
  opt.clock_mapped = offset->count() > 0 || drift->count() > 0;
  if (opt.clock_mapped && opt.fast) {
    fmt::print(stderr, "tonus-band-sim: --clock-offset-us and --clock-drift-ppm need real time (no --fast)\n");
    return 2;
  }
  if (opt.synthetic.empty() && opt.recording.empty()) {
    fmt::print(stderr, "tonus-band-sim: give --synthetic NAME or --recording FILE\n");
    return 2;
  }
  if (!opt.synthetic.empty() && !(opt.seconds > 0.0)) {
    fmt::print(stderr, "tonus-band-sim: --synthetic needs --seconds > 0\n");
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return run(opt);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return cli_main(argc, argv);
  } catch (const std::exception& e) {  // e.g. an unwritable --json path
    std::fputs("tonus-band-sim: ", stderr);
    std::fputs(e.what(), stderr);
    std::fputs("\n", stderr);
  } catch (...) {
    std::fputs("tonus-band-sim: unknown error\n", stderr);
  }
  return 1;
}
