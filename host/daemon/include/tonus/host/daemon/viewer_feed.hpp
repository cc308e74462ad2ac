// tonusd's live viewer (host/viewer, docs/viewer.md): a thread of its own
// takes the physics core's viewer snapshot (a triple buffer the core fills
// every few ticks) at viewer.rate_hz, poses the bodies of simulation B and of
// the reference (forward kinematics on its own scratch Data), finds the ZMP
// (the centre of pressure of the avatar's ground contacts) and the support
// polygon (their convex hull), and publishes the frame to the page. The
// physics thread never waits for it; a slow browser only costs the server.
// The page's controls are the control API's routes (control::route).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tonus/host/control/api.hpp"
#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/viewer/frame.hpp"
#include "tonus/host/viewer/json.hpp"
#include "tonus/sim/data.hpp"

namespace tonus::viewer {
class ViewerServer;
struct ViewerStats;
}  // namespace tonus::viewer

namespace tonus::daemon {

// The scene the page builds its meshes from: bones, shapes, groups, targets.
viewer::Scene make_viewer_scene(const sim::Model& model, const std::string& mode);

// Frames from viewer snapshots. Band, metrics and playback are left for the
// caller. The ZMP: where the avatar's body touches the ground (a free root),
// the centre of pressure of those contacts, exactly; where the hips are
// carried (the kinematic root of VTuber setups, no ground contact), the
// cart-table ZMP of the whole-body centre of mass, p = c - c_z / (c_z'' + g)
// c'', its acceleration from the last three snapshots. The support polygon:
// the hull of the ground contacts, or of the soles' points within 3 cm of the
// ground.
class ViewerFrameBuilder {
 public:
  explicit ViewerFrameBuilder(const sim::Model& model);
  void build(const ViewerSnapshot& s, viewer::Frame& out);

 private:
  void support_from_soles(viewer::Frame& out) const;

  const sim::Model& model_;
  std::unique_ptr<sim::Data> scratch_;  // forward kinematics
  std::vector<int> sole_geoms_;         // the feet's and toes' shapes
  std::array<sim::Vec3, 3> com_{};      // the last three centres of mass, oldest first
  std::array<double, 3> com_t_{};
  int coms_ = 0;
};

class ViewerFeed {
 public:
  // What the daemon adds to each frame: the band's state, the tick figures, the playback position.
  using Extras = std::function<void(viewer::Frame& frame)>;
  using Playback = std::function<std::string(const viewer::PlaybackMessage& command)>;

  ViewerFeed(const ViewerConfig& config, const sim::Model& model, PhysicsCore& core, std::string mode);
  ~ViewerFeed();
  ViewerFeed(const ViewerFeed&) = delete;
  ViewerFeed& operator=(const ViewerFeed&) = delete;

  // Binds the page's port and starts the thread; false and `error` when the
  // port cannot be had. `control` answers the page's requests (nullptr: 503);
  // `read_only` (a replay: the inputs are the recording's) refuses all but GET.
  bool start(std::string& error, control::Handler* control, bool read_only, Extras extras, Playback playback);
  void stop();

  [[nodiscard]] std::string url() const;
  [[nodiscard]] int port() const;
  [[nodiscard]] std::uint64_t frames() const { return frames_.load(); }
  [[nodiscard]] viewer::ViewerStats stats() const;

 private:
  void run();

  ViewerConfig config_;
  const sim::Model& model_;
  PhysicsCore& core_;
  std::string mode_;
  std::unique_ptr<viewer::ViewerServer> server_;
  ViewerFrameBuilder builder_;
  Extras extras_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_{0};
};

}  // namespace tonus::daemon
