#include "tonus/host/daemon/control_handler.hpp"

#include <chrono>

#include "tonus/host/daemon/daemon.hpp"

namespace tonus::daemon {

control::Reply DaemonControl::spawn_gift(const control::GiftRequest& r) {
  avatar::ThrowBall ball;
  avatar::DropCube cube;
  const bool is_ball = r.kind == control::GiftKind::ball;
  const sim::Bone bone = r.bone.value_or(is_ball ? ball.target : cube.target);
  if (r.mass_kg) ball.mass_kg = cube.mass_kg = *r.mass_kg;
  if (r.size_m) {
    ball.radius_m = *r.size_m / 2.0;  // the API gives a ball's diameter
    cube.edge_m = *r.size_m;
  }
  if (r.speed_mps) ball.speed_mps = *r.speed_mps;
  if (r.height_m) cube.height_m = *r.height_m;
  if (r.lifetime_s) ball.lifetime_s = cube.lifetime_s = *r.lifetime_s;
  std::string error;
  const std::uint32_t id = daemon_.spawn_gift(is_ball ? GiftKind::ball : GiftKind::cube, bone, &ball, &cube, error);
  if (id == 0) return control::Reply::error(503, error);
  // Queued: the physics thread may still refuse it (a full scene); /status and the log say so.
  return control::Reply::ok({{"id", id}, {"kind", is_ball ? "ball" : "cube"}, {"bone", std::string(sim::name(bone))}},
                            202);
}

control::Reply DaemonControl::clear_gifts() {
  if (!daemon_.clear_gifts()) return control::Reply::error(503, "the command queue is full");
  return control::Reply::ok({{"cleared", true}}, 202);
}

control::Reply DaemonControl::set_stiffness_override(const std::optional<control::Levels>& levels) {
  std::optional<Levels> l;
  if (levels) l = Levels{(*levels)[0], (*levels)[1], (*levels)[2], (*levels)[3]};
  if (!daemon_.set_stiffness_override(l)) return control::Reply::error(503, "the command queue is full");
  nlohmann::json body{{"override", levels.has_value()}};
  if (levels) body["levels"] = *levels;
  return control::Reply::ok(body, 202);
}

control::Reply DaemonControl::calibrate(control::CalibrationCommand command) {
  std::future<std::string> f = daemon_.calibrate(std::string(control::to_string(command)));
  if (f.wait_for(std::chrono::milliseconds(1500)) != std::future_status::ready) {
    return control::Reply::error(504, "the band did not answer in time");
  }
  const std::string error = f.get();
  if (!error.empty()) return control::Reply::error(409, error);
  return control::Reply::ok({{"calibration", std::string(control::to_string(command))}, {"accepted", true}});
}

control::Reply DaemonControl::status() { return control::Reply::ok(daemon_.status_json()); }

}  // namespace tonus::daemon
