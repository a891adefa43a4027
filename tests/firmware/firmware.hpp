// SPDX-License-Identifier: MIT
// The bare-metal side of the firmware check (tests/firmware): a reset handler that turns the FPU on and calls main,
// and output and exit through Arm semihosting, which QEMU's -semihosting serves. No C library start-up, no stdio, no
// heap: what a control loop on a microcontroller links. The same program compiled for the host writes to stdout.
#pragma once

#include <cstdint>
#include <cstring>

/// The program (a function of the C linkage, called by the reset handler or the host's main).
extern "C" int firmware_main();

namespace firmware {

#if defined(__arm__)
inline int semihost(int operation, const void* argument) {
  register int r0 __asm__("r0") = operation;
  register const void* r1 __asm__("r1") = argument;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}
inline void write(const char* text) { semihost(0x04, text); }  // SYS_WRITE0
[[noreturn]] inline void exit(int status) {
  semihost(0x18, reinterpret_cast<const void*>(status == 0 ? 0x20026 : 0x20024));  // SYS_EXIT: exited, or error
  for (;;) {
  }
}
#else
void write(const char* text);
[[noreturn]] void exit(int status);
#endif

/// Writes `label` and the bit patterns of the n values, as hexadecimal words (exact, and no printf of floats,
/// which would link double arithmetic into a float image).
template <class Real>
void write_bits(const char* label, const Real* values, int n) {
  static_assert(sizeof(Real) == 4 || sizeof(Real) == 8, "float or double");
  char line[32];
  write(label);
  for (int i = 0; i < n; ++i) {
    std::uint64_t bits = 0;
    if constexpr (sizeof(Real) == 4) {
      std::uint32_t b;
      std::memcpy(&b, &values[i], 4);
      bits = b;
    } else {
      std::memcpy(&bits, &values[i], 8);
    }
    int digits = 2 * static_cast<int>(sizeof(Real));
    line[0] = ' ';
    for (int d = 0; d < digits; ++d) line[1 + d] = "0123456789abcdef"[(bits >> (4 * (digits - 1 - d))) & 0xf];
    line[1 + digits] = '\0';
    write(line);
  }
  write("\n");
}

/// Writes `label` and the unsigned number n.
inline void write_number(const char* label, unsigned long n) {
  char digits[24];
  int i = 23;
  digits[i] = '\0';
  do {
    digits[--i] = static_cast<char>('0' + n % 10);
    n /= 10;
  } while (n != 0);
  write(label);
  write(digits + i);
}

}  // namespace firmware
