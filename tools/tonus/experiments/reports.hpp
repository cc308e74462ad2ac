// The experiments' reports: JSON (the interface outside checks read) and SVG
// figures, plus the goals each experiment is judged by.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "brace.hpp"
#include "cube_on_hand.hpp"
#include "track.hpp"

namespace tonus::experiments {

struct Goal {
  std::string what;
  bool met = false;
};

std::vector<Goal> cube_goals(const CubeOnHandResult& r);
nlohmann::json to_json(const CubeOnHandResult& r);
bool write_cube_svg(const std::string& path, const CubeOnHandResult& r, std::string& error);

std::vector<Goal> brace_goals(const BraceResult& r);
nlohmann::json to_json(const BraceResult& r);
bool write_brace_svg(const std::string& path, const BraceResult& r, std::string& error);

std::vector<Goal> track_goals(const TrackResult& r);
nlohmann::json to_json(const TrackResult& r);
bool write_track_svg(const std::string& path, const TrackResult& r, std::string& error);

nlohmann::json goals_json(const std::vector<Goal>& goals);

}  // namespace tonus::experiments
