// SPDX-License-Identifier: MIT
// Proves that dop853.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/dop853.hpp"
