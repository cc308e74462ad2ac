// Virtual objects (balls, cubes) added and removed between steps, up to
// kMaxObjects. A handle carries the slot and its generation so a handle kept
// after remove_object() cannot touch the slot's next occupant.
#pragma once

#include <cstdint>
#include <string_view>

#include "tonus/sim/data.hpp"

namespace tonus::sim {

struct ObjectHandle {
  int slot = -1;
  std::uint32_t generation = 0;
  [[nodiscard]] bool valid() const { return slot >= 0; }
};

enum class ObjectError : std::uint8_t { none, full, bad_shape, bad_mass, bad_pose, bad_velocity, bad_material };
std::string_view to_string(ObjectError e);

struct AddObjectResult {
  ObjectHandle handle;
  ObjectError error = ObjectError::none;
};

// Checks the spec (spheres and boxes only, finite positive sizes and mass,
// finite pose and velocity, friction >= 0, restitution in [0, 1]); the
// quaternion is normalised. Does not allocate.
AddObjectResult add_object(Data& data, const ObjectSpec& spec);

// False when the handle is stale or out of range.
bool remove_object(Data& data, ObjectHandle handle);

// The object behind a live handle, or nullptr.
Object* find_object(Data& data, ObjectHandle handle);
const Object* find_object(const Data& data, ObjectHandle handle);

int active_object_count(const Data& data);

}  // namespace tonus::sim
