// Parsing of expression strings with GiNaC's parser, exactly: decimal literals become rationals so
// that zero tests stay exact, and unknown names are errors.
#pragma once

#include <ginac/ginac.h>

#include <string>

namespace hamel {

/// Rewrites decimal literals (1.5, 2e-3, .25) as exact rationals "(3/2)"; other text is unchanged.
std::string exact_decimals(const std::string& text);

/// Parses `text` with the symbols of `table` only. Throws std::invalid_argument with GiNaC's message
/// (unknown symbol, syntax) on failure.
GiNaC::ex parse_expression(const std::string& text, const GiNaC::symtab& table);

/// The exact rational with the shortest decimal spelling that reads back as `value` (0.1 → 1/10), so
/// that numbers from the command line or parameter defaults evaluate without binary rounding.
GiNaC::ex exact_number(double value);

/// True if `name` is a valid C++ identifier that is not a keyword or a reserved name of the tool.
bool is_valid_identifier(const std::string& name, std::string* why = nullptr);

}  // namespace hamel
