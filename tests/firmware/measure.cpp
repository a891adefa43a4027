// SPDX-License-Identifier: MIT
// Per kernel of a package on a Cortex-M under QEMU (tools/firmware-table.sh, docs/firmware.md): the stack a call
// takes, of the kernel and of its work-space form (stack painting: the stack below the caller is filled with a
// pattern, the kernel called, the deepest word changed found), and the instructions one call executes (SysTick
// under qemu -icount shift=0, where virtual time advances one nanosecond per instruction, calibrated on a loop of
// known length). Prints one line per kernel: name n_work stack stack_work instructions.
// PACKAGE: the package's namespace; PACKAGE_HEADER: its header.
#include "firmware.hpp"

#include PACKAGE_HEADER

namespace {

namespace pkg = PACKAGE;
using real = pkg::real;

constexpr int largest_work() {
  int most = 1;
  for (const pkg::kernel_info& k : pkg::kernel_table) most = k.n_work > most ? k.n_work : most;
  return most;
}
real work[largest_work()];
real out[pkg::n_out_max > 0 ? pkg::n_out_max : 1];
real x[pkg::n_state];
real inputs[pkg::n_inputs > 0 ? pkg::n_inputs : 1];

extern "C" char stack_bottom[];
constexpr std::uint32_t pattern = 0x5AA5C33Cu;

volatile std::uint32_t* const syst_csr = reinterpret_cast<volatile std::uint32_t*>(0xE000E010u);
volatile std::uint32_t* const syst_rvr = reinterpret_cast<volatile std::uint32_t*>(0xE000E014u);
volatile std::uint32_t* const syst_cvr = reinterpret_cast<volatile std::uint32_t*>(0xE000E018u);

__attribute__((noinline)) void call(const pkg::kernel_info& k, bool with_work) {
  if (with_work)
    k.work_function(real(0), x, pkg::default_parameters, inputs, out, work);
  else
    k.function(real(0), x, pkg::default_parameters, inputs, out);
}

/// Bytes of stack one call of k takes below this function's stack pointer (the 8 bytes of `call`'s frame included).
__attribute__((noinline)) unsigned long stack_of(const pkg::kernel_info& k, bool with_work) {
  std::uintptr_t sp;
  __asm__ volatile("mov %0, sp" : "=r"(sp));
  std::uint32_t* const top = reinterpret_cast<std::uint32_t*>(sp & ~std::uintptr_t{7});
  std::uint32_t* const bottom = reinterpret_cast<std::uint32_t*>(stack_bottom);
  for (volatile std::uint32_t* w = bottom; w < top; ++w) *w = pattern;
  call(k, with_work);
  const std::uint32_t* w = bottom;
  while (w < top && *w == pattern) ++w;
  return static_cast<unsigned long>(reinterpret_cast<const char*>(top) - reinterpret_cast<const char*>(w));
}

std::uint32_t ticks_since(std::uint32_t start) { return (start - *syst_cvr) & 0xFFFFFFu; }

/// SysTick ticks of 2^21 instructions: a loop of 2 instructions per turn (subs, bne) run 2^20 times.
std::uint32_t ticks_of_2_21_instructions() {
  const std::uint32_t start = *syst_cvr;
  std::uint32_t n = 1u << 20;
  __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n));
  return ticks_since(start);
}

}  // namespace

int firmware_main() {
  *syst_rvr = 0xFFFFFFu;
  *syst_cvr = 0;
  *syst_csr = 5;  // enabled, processor clock, no interrupt
  for (int i = 0; i < pkg::n_state; ++i) x[i] = real(0.05) * static_cast<real>(i + 1);
  const std::uint64_t calibration = ticks_of_2_21_instructions();
  for (const pkg::kernel_info& k : pkg::kernel_table) {
    const unsigned long stack = stack_of(k, false), stack_work = stack_of(k, true);
    constexpr int repeats = 16;
    const std::uint32_t start = *syst_cvr;
    for (int r = 0; r < repeats; ++r) call(k, false);
    const std::uint64_t ticks = ticks_since(start);
    const std::uint64_t instructions =
        (ticks * (std::uint64_t{1} << 21) + calibration * repeats / 2) / (calibration * repeats);
    firmware::write(k.name);
    firmware::write_number(" ", static_cast<unsigned long>(k.n_work));
    firmware::write_number(" ", stack);
    firmware::write_number(" ", stack_work);
    firmware::write_number(" ", static_cast<unsigned long>(instructions));
    firmware::write("\n");
  }
  return 0;
}
