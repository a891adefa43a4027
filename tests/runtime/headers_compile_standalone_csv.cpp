// SPDX-License-Identifier: MIT
// Proves that csv.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/csv.hpp"
