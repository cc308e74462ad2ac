# MuJoCo (Debian libmujoco-dev 2.2.2), the independent reference that tests
# and benchmarks compare the physics core against. Found once at the top so
# every directory sees the same imported target.
#
# Debian's package exports /usr/include/libqhull_r/ as an include directory
# of mujoco::mujoco without shipping it (MuJoCo's public headers do not need
# it); CMake refuses non-existent include paths, so keep only the real ones.
find_package(mujoco REQUIRED CONFIG)
get_target_property(_tonus_mujoco_includes mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
set(_tonus_mujoco_existing)
foreach(dir IN LISTS _tonus_mujoco_includes)
  if(EXISTS "${dir}")
    list(APPEND _tonus_mujoco_existing "${dir}")
  endif()
endforeach()
set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_tonus_mujoco_existing}")
