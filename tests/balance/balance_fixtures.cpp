#include "balance_fixtures.hpp"

#include <doctest/doctest.h>

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

}  // namespace tonus::balance::test
