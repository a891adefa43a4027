// SPDX-License-Identifier: MIT
// Proves that ldlt.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/ldlt.hpp"
