// The tracker IK evaluation as JSON (the fields outside checks read) and as
// an SVG plot.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "ik_eval.hpp"

namespace tonus::experiments {

nlohmann::json to_json(const IkEvalResult& r);
bool write_ik_svg(const std::string& path, const IkEvalResult& r, std::string& error);

}  // namespace tonus::experiments
