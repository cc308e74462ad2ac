#include "semihosting.hpp"

#include <cstdint>

namespace tonus::f405::semihosting {

namespace {

constexpr std::uint32_t kSysWrite0 = 0x04;
constexpr std::uint32_t kSysExit = 0x18;
constexpr std::uint32_t kApplicationExit = 0x20026;  // ADP_Stopped_ApplicationExit
constexpr std::uint32_t kRunTimeError = 0x20023;     // ADP_Stopped_RunTimeErrorUnknown

std::uint32_t call(std::uint32_t op, const void* arg) {
  register std::uint32_t r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

}  // namespace

void write(const char* text) { call(kSysWrite0, text); }

void exit(bool success) {
  // On AArch32 the argument is the reason code itself.
  call(kSysExit, reinterpret_cast<const void*>(success ? kApplicationExit : kRunTimeError));
  for (;;) {
  }
}

}  // namespace tonus::f405::semihosting
