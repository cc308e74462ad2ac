# Project-wide options, warning sets and the freestanding target property.

option(TONUS_TARGET_ARM "Cross build for the Cortex-M4F band (set by the arm preset)" OFF)
option(TONUS_FUZZ "Also build the libFuzzer targets (clang only; the asan and fuzz presets)" OFF)
option(TONUS_FUZZ_ONLY "Build only the libFuzzer targets and what they link (the fuzz preset)" OFF)
option(TONUS_WERROR "Treat warnings as errors" ON)

# Real mocap and EMG recordings (../shared/data beside the checkout) that tests
# read; they are not copied into the repository (see their SOURCES.md).
set(_tonus_shared_default "${PROJECT_SOURCE_DIR}/../shared/data")
if(NOT EXISTS "${_tonus_shared_default}" AND EXISTS "/work/shared/data")
  set(_tonus_shared_default "/work/shared/data")
endif()
set(TONUS_SHARED_DATA_DIR "${_tonus_shared_default}" CACHE PATH "Folder holding bvh/ and emg/ recordings")
cmake_path(ABSOLUTE_PATH TONUS_SHARED_DATA_DIR NORMALIZE)

# Warnings for every target of ours; third-party headers come in as SYSTEM.
add_library(tonus_warnings INTERFACE)
target_compile_options(tonus_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
  -Wcast-align -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual
  -Wnull-dereference -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough
  $<$<BOOL:${TONUS_WERROR}>:-Werror>)
# clang also flags every float passed where a double is taken (the tests'
# checks of the firmware's float results); gcc's narrower rule, which the
# release and Cortex-M4F builds apply to every file, catches the promotions
# that cost the FPU.
target_compile_options(tonus_warnings INTERFACE $<$<CXX_COMPILER_ID:Clang>:-Wno-double-promotion>)

# Freestanding subset for code that runs on the band: no exceptions, no RTTI,
# no thread-safe static guards (they pull in __cxa_guard_* and may lock).
# The heap ban is enforced at link time by tonus_poison_heap() below.
function(tonus_freestanding target)
  target_compile_options(${target} PRIVATE
    -fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-asynchronous-unwind-tables)
  set_property(TARGET ${target} PROPERTY TONUS_FREESTANDING ON)
endfunction()

# Link-time heap poison: every allocation entry point is redirected with
# --wrap to a symbol that is never defined, so any object file of ours that
# references malloc/new/exceptions fails to link.
# operator new and new[] are mangled with size_t's type: unsigned long (m) on
# x86-64, unsigned int (j) on the Cortex-M4; both are listed.
set(TONUS_HEAP_SYMBOLS
  malloc calloc realloc free aligned_alloc posix_memalign memalign
  _Znwm _Znam _ZnwmRKSt9nothrow_t _ZnamRKSt9nothrow_t
  _ZnwmSt11align_val_t _ZnamSt11align_val_t
  _Znwj _Znaj _ZnwjRKSt9nothrow_t _ZnajRKSt9nothrow_t
  _ZnwjSt11align_val_t _ZnajSt11align_val_t
  __cxa_allocate_exception __cxa_throw)
function(tonus_poison_heap target)
  foreach(sym IN LISTS TONUS_HEAP_SYMBOLS)
    target_link_options(${target} PRIVATE "LINKER:--wrap=${sym}")
  endforeach()
endfunction()
