// Names of the gift errors.
#include "tonus/host/avatar/gifts.hpp"

namespace tonus::avatar {

std::string_view to_string(GiftError e) {
  switch (e) {
    case GiftError::none: return "none";
    case GiftError::full: return "every object slot is taken";
    case GiftError::bad_target: return "no shape on that bone";
    case GiftError::bad_params: return "mass, size, speed, height or lifetime out of range";
    case GiftError::not_found: return "no such gift";
  }
  return "?";
}

}  // namespace tonus::avatar
