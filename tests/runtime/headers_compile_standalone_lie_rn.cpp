// SPDX-License-Identifier: MIT
// Proves that lie/rn.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/lie/rn.hpp"
