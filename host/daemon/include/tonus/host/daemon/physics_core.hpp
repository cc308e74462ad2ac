// One tick of tonusd's physics thread, with no thread or clock of its own (the
// caller passes the tick's host time), so tests drive it tick by tick:
//   read:   band reports -> StiffnessInput (stale -> safe default);
//           tracker poses -> PoseBuffer (interpolated at the tick, held, eased);
//           commands (gifts, clear, stiffness override);
//   update: the avatar controller (dual PD: A stiff -> tau_ff -> B weak x stiffness + gifts);
//           each gift's reaction measured (peak deflection of its bone, B against A);
//   write:  the snapshot (triple buffer) and events (queue) for the other threads.
// Everything is allocated in create(); tick() allocates nothing, never blocks,
// never logs.
#pragma once

#include <readerwriterqueue/readerwriterqueue.h>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "tonus/host/avatar/controller.hpp"
#include "tonus/host/daemon/histogram.hpp"
#include "tonus/host/daemon/messages.hpp"
#include "tonus/host/daemon/pose_buffer.hpp"
#include "tonus/host/daemon/stiffness_input.hpp"
#include "tonus/host/daemon/triple_buffer.hpp"

namespace tonus::daemon {

class Recorder;

struct PhysicsCoreConfig {
  avatar::AvatarConfig avatar;
  StiffnessInputConfig stiffness;
  PoseBufferConfig pose;
  double reaction_window_s = 2.0;  // a gift's reaction is measured over this long after it appears
  int viewer_every_ticks = 0;      // publish a ViewerSnapshot every this many ticks (0: never)
};

// Queue capacities (fixed; a full queue drops the newest item and counts it).
inline constexpr std::size_t kBandQueue = 1024;  // 1 s of 1 kHz reports
inline constexpr std::size_t kPoseQueue = 256;   // 2 s of a 120 Hz tracker
inline constexpr std::size_t kCommandQueue = 64;
inline constexpr std::size_t kEventQueue = 1024;

// Counters over the core's life (read by the owning thread after ticks).
struct CoreStats {
  std::uint64_t ticks = 0;
  std::uint64_t band_samples = 0;
  std::uint64_t pose_samples = 0;
  std::uint64_t commands = 0;
  std::uint64_t events_dropped = 0;       // the event queue was full
  std::uint64_t reactions_untracked = 0;  // more gifts at once than reaction slots
  std::uint64_t avatar_resets = 0;
  // FNV-1a over every tick's output (B's configuration, the objects' poses,
  // the applied stiffness): equal hashes, equal outputs; a replay checks it.
  std::uint64_t output_hash = 14695981039346656037ULL;
  Levels stiffness_min{1.0, 1.0, 1.0, 1.0};  // applied, over every tick
  Levels stiffness_max{0.0, 0.0, 0.0, 0.0};
};

// What the paced thread ticks (PhysicsCore; a test's stand-in that stalls).
class TickTarget {
 public:
  virtual ~TickTarget() = default;
  virtual void tick(std::int64_t now_us) = 0;
  // Called by the paced thread between ticks when it closes a status
  // interval: the band latency of the interval (device sample -> tick), us.
  virtual void close_interval(double& latency_p50_us, double& latency_p99_us) { latency_p50_us = latency_p99_us = 0.0; }

 protected:
  TickTarget() = default;
  TickTarget(const TickTarget&) = default;
  TickTarget& operator=(const TickTarget&) = default;
};

class PhysicsCore final : public TickTarget {
 public:
  // The model must outlive the core. nullptr and `error` when the config does not fit the model.
  static std::unique_ptr<PhysicsCore> create(const sim::Model& model, const PhysicsCoreConfig& config,
                                             std::string& error);

  // Producer sides (one producer each; push_command may be called from any thread).
  bool push_band(const BandSample& s) { return band_.try_enqueue(s) || count_drop(band_dropped_); }
  bool push_pose(const PoseSample& s) { return pose_.try_enqueue(s) || count_drop(pose_dropped_); }
  bool push_command(const Command& c);

  // Every input a tick consumes goes to the recorder too (set before the
  // physics thread starts; nullptr: not recording).
  void set_recorder(Recorder* recorder) { recorder_ = recorder; }

  // Back to the state create() left (the controller rebuilt, the queues
  // emptied, the statistics and the output hash reset), for a replay that
  // seeks backwards. Allocates: never on the paced thread. false and `error`
  // if the controller cannot be rebuilt (it was built once from the same config).
  bool restart(std::string& error);

  // One tick at host time now_us (the tick's deadline).
  void tick(std::int64_t now_us) override;
  void close_interval(double& latency_p50_us, double& latency_p99_us) override;

  // Consumer sides for the other threads: one snapshot buffer for the
  // output thread, one for the status (main) thread.
  TripleBuffer<Snapshot>& snapshots() { return snapshots_; }
  TripleBuffer<Snapshot>& status_snapshots() { return status_snapshots_; }
  moodycamel::ReaderWriterQueue<Event>& events() { return events_; }
  TripleBuffer<ViewerSnapshot>& viewer_snapshots() { return viewer_snapshots_; }

  [[nodiscard]] const CoreStats& stats() const { return stats_; }
  [[nodiscard]] std::uint64_t band_dropped() const { return band_dropped_.load(); }
  [[nodiscard]] std::uint64_t pose_dropped() const { return pose_dropped_.load(); }
  [[nodiscard]] std::uint64_t commands_dropped() const { return command_dropped_.load(); }
  [[nodiscard]] const avatar::AvatarController& controller() const { return *controller_; }
  [[nodiscard]] const Histogram& band_latency() const { return band_latency_; }  // device sample -> tick, us
  [[nodiscard]] const PoseBuffer& pose_buffer() const { return pose_buffer_; }

 private:
  struct Reaction {
    bool active = false;
    std::uint32_t id = 0;
    avatar::GiftId gift;
    GiftKind kind = GiftKind::cube;
    sim::Bone bone = sim::Bone::Hips;
    double start_s = 0.0;
    double stiffness = 0.0;
    double natural_hz = 0.0;
    sim::Vec3 baseline = sim::Vec3::Zero();  // B - A at the bone when the gift appeared
    double peak_m = 0.0;
  };

  PhysicsCore(const sim::Model& model, const PhysicsCoreConfig& config, avatar::AvatarController controller);
  void start_standing();  // the constructor's and restart()'s first pose and stiffness
  static bool count_drop(std::atomic<std::uint64_t>& n) {
    n.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  [[nodiscard]] Event event(Event::Kind kind) const;  // stamped with the physics time
  void emit(const Event& e);
  void apply(const Command& c);
  void spawn(const Command& c);
  void track_reactions();
  [[nodiscard]] sim::Vec3 bone_offset(sim::Bone b) const;  // B's centre of mass minus A's
  [[nodiscard]] int group_of(sim::Bone b) const;           // the bone's stiffness group, or avatar::kNoGroup
  [[nodiscard]] double group_stiffness(sim::Bone b) const;
  [[nodiscard]] double group_hz(sim::Bone b) const;
  void publish(std::int64_t now_us);
  void publish_viewer(const Snapshot& s);

  const sim::Model* model_;
  PhysicsCoreConfig config_;
  std::unique_ptr<avatar::AvatarController> controller_;
  StiffnessInput stiffness_;
  PoseBuffer pose_buffer_;
  moodycamel::ReaderWriterQueue<BandSample> band_{kBandQueue};
  moodycamel::ReaderWriterQueue<PoseSample> pose_{kPoseQueue};
  moodycamel::ReaderWriterQueue<Command> commands_{kCommandQueue};
  std::mutex command_producers_;  // serialises producers only; the physics side never locks
  moodycamel::ReaderWriterQueue<Event> events_{kEventQueue};
  TripleBuffer<Snapshot> snapshots_;
  TripleBuffer<Snapshot> status_snapshots_;
  TripleBuffer<ViewerSnapshot> viewer_snapshots_;
  std::atomic<std::uint64_t> band_dropped_{0}, pose_dropped_{0}, command_dropped_{0};
  std::optional<Levels> override_;
  avatar::TickInput input_;
  std::array<Reaction, sim::kMaxObjects> reactions_{};
  std::array<std::uint32_t, sim::kMaxObjects> object_ids_{};  // the request id of each object slot
  std::array<GiftKind, sim::kMaxObjects> object_kinds_{};
  Histogram band_latency_{10.0, 20000};  // 10 us bins up to 200 ms
  Histogram interval_latency_{10.0, 20000};
  std::int64_t band_arrival_us_ = 0;
  bool band_live_ = false;
  PoseState pose_state_ = PoseState::none;
  CoreStats stats_;
  Recorder* recorder_ = nullptr;
};

}  // namespace tonus::daemon
