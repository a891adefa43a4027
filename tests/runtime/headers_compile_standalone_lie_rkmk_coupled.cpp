// SPDX-License-Identifier: MIT
// Proves that lie/rkmk_coupled.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/lie/rkmk_coupled.hpp"
