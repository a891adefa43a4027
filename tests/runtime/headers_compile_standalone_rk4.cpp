// SPDX-License-Identifier: MIT
// Proves that rk4.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/rk4.hpp"
