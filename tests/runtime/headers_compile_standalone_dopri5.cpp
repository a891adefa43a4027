// SPDX-License-Identifier: MIT
// Proves that dopri5.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/dopri5.hpp"
