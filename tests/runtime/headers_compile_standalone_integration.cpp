// SPDX-License-Identifier: MIT
// Proves that integration.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/integration.hpp"
