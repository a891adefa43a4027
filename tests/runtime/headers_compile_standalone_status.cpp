// SPDX-License-Identifier: MIT
// Proves that status.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/status.hpp"
