// SPDX-License-Identifier: MIT
// Proves that radau5.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/radau5.hpp"
