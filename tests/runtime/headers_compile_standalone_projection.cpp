// SPDX-License-Identifier: MIT
// Proves that projection.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/projection.hpp"
