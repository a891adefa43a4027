// SPDX-License-Identifier: MIT
// Proves that lie/so3.hpp compiles as the first and only include of a translation unit.
#include "hamel/runtime/lie/so3.hpp"
