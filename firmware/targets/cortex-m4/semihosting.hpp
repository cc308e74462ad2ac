// ARM semihosting (the debugger or QEMU services calls made with BKPT 0xAB):
// used only by the self-test image to print and to exit with a status.
#pragma once

namespace tonus::f405::semihosting {

void write(const char* text);          // SYS_WRITE0
[[noreturn]] void exit(bool success);  // SYS_EXIT

}  // namespace tonus::f405::semihosting
