// GiNaC::Digits (the precision of evalf and of CLN floats) set for a scope and restored on every exit from it,
// exceptions included.
#pragma once

#include <ginac/ginac.h>

namespace hamel {

/// Sets GiNaC::Digits for its lifetime and restores the previous value.
class DigitsGuard {
 public:
  explicit DigitsGuard(long digits) : saved_(GiNaC::Digits) { GiNaC::Digits = digits; }
  ~DigitsGuard() { GiNaC::Digits = saved_; }
  DigitsGuard(const DigitsGuard&) = delete;
  DigitsGuard& operator=(const DigitsGuard&) = delete;

 private:
  long saved_;
};

}  // namespace hamel
