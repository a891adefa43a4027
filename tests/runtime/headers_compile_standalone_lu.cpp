// SPDX-License-Identifier: MIT
// Proves that lu.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/lu.hpp"
