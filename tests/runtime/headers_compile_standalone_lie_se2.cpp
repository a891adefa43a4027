// SPDX-License-Identifier: MIT
// Proves that lie/se2.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/lie/se2.hpp"
