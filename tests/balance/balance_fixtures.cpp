#include "balance_fixtures.hpp"

#include <doctest/doctest.h>

#include <cmath>

namespace tonus::balance::test {

Loaded load(const std::string& path, const ConvertOptions& options) {
  Loaded l;
  motion::ReadResult r = motion::read_bvh_file(path);
  REQUIRE_MESSAGE(r.ok(), path << ": " << (r.error ? r.error->message : std::string()));
  l.clip = std::move(r.clip);
  l.mapping = map_skeleton(l.clip);
  REQUIRE_MESSAGE(l.mapping.ok(), l.mapping.error);
  l.conversion = convert_motion(l.clip, l.mapping, options);
  REQUIRE_MESSAGE(l.conversion.ok(), l.conversion.error);
  return l;
}

std::vector<std::size_t> rotation_jumps(const motion::Clip& clip, double degrees, double lock_margin_deg) {
  const std::vector<std::size_t> start = motion::channel_columns(clip);
  std::vector<std::size_t> jumps(clip.channel_count(), 0);
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    std::vector<std::size_t> rotations;
    for (std::size_t c = 0; c < clip.joints[j].channels.size(); ++c)
      if (motion::is_rotation(clip.joints[j].channels[c])) rotations.push_back(start[j] + c);
    const auto near_lock = [&](std::size_t f) {
      if (rotations.size() != 3 || lock_margin_deg <= 0.0) return false;
      return std::abs(std::abs(std::remainder(clip.frame(f)[rotations[1]], 360.0)) - 90.0) < lock_margin_deg;
    };
    for (const std::size_t column : rotations) {
      for (std::size_t f = 1; f < clip.frame_count; ++f) {
        if (near_lock(f) || near_lock(f - 1)) continue;
        if (std::abs(clip.frame(f)[column] - clip.frame(f - 1)[column]) > degrees) ++jumps[column];
      }
    }
  }
  return jumps;
}

std::string column_name(const motion::Clip& clip, std::size_t column) {
  const std::vector<std::size_t> start = motion::channel_columns(clip);
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    if (column >= start[j] && column < start[j + 1]) {
      return clip.joints[j].name + " " + std::string(motion::channel_name(clip.joints[j].channels[column - start[j]]));
    }
  }
  return "column " + std::to_string(column);
}

HumanMotion without_leading_tpose(const HumanMotion& m) {
  HumanMotion cut = m;
  cut.frames.erase(cut.frames.begin(), cut.frames.begin() + static_cast<std::ptrdiff_t>(m.first_frame));
  cut.first_frame = 0;
  return cut;
}

}  // namespace tonus::balance::test
