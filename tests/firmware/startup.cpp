// SPDX-License-Identifier: MIT
// Start-up of the firmware check's images on QEMU's MPS2 boards (mps2.ld): the vector table (initial stack pointer
// and reset handler; any fault ends the run through semihosting with an error), the FPU enabled, main called.
#include "firmware.hpp"

extern "C" {
extern char stack_top[];
[[noreturn]] void reset_handler();
[[noreturn]] void fault_handler();
}

[[noreturn]] void reset_handler() {
  // CPACR: full access to coprocessors 10 and 11 (the FPU) before the first floating-point instruction.
  volatile std::uint32_t* const cpacr = reinterpret_cast<volatile std::uint32_t*>(0xE000ED88u);
  *cpacr = *cpacr | (0xFu << 20);
  __asm__ volatile("dsb\n\tisb" ::: "memory");
  firmware::exit(firmware_main());
}

[[noreturn]] void fault_handler() {
  firmware::write("fault\n");
  firmware::exit(3);
}

using Handler = void (*)();
__attribute__((section(".vectors"), used)) const Handler vectors[16] = {reinterpret_cast<Handler>(stack_top),
                                                                        reset_handler,
                                                                        fault_handler,
                                                                        fault_handler,
                                                                        fault_handler,
                                                                        fault_handler,
                                                                        fault_handler,
                                                                        nullptr,
                                                                        nullptr,
                                                                        nullptr,
                                                                        nullptr,
                                                                        fault_handler,
                                                                        fault_handler,
                                                                        nullptr,
                                                                        fault_handler,
                                                                        fault_handler};
