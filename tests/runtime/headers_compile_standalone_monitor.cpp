// SPDX-License-Identifier: MIT
// Proves that monitor.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/monitor.hpp"
