// SPDX-License-Identifier: MIT
// firmware.hpp's output and exit for the host build of the firmware check's programs.
#include "firmware.hpp"

#include <cstdio>
#include <cstdlib>

namespace firmware {
void write(const char* text) { std::fputs(text, stdout); }
void exit(int status) {
  std::fflush(stdout);
  std::exit(status);
}
}  // namespace firmware

int main() { firmware::exit(firmware_main()); }
