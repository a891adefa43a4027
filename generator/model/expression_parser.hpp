// Parsing of expression strings with GiNaC's parser, exactly: decimal literals become rationals so
// that zero tests stay exact, and unknown names are errors.
#pragma once

#include <ginac/ginac.h>

#include <cstddef>
#include <string>
#include <vector>

namespace hamel {

/// Rewrites decimal literals (1.5, 2e-3, .25) as exact rationals "(3/2)"; other text is unchanged.
/// Throws std::invalid_argument for a decimal exponent beyond ±max_decimal_exponent.
std::string exact_decimals(const std::string& text);

/// Largest decimal exponent accepted in a literal (1e308 is about the largest double).
constexpr long max_decimal_exponent = 1000;
/// Deepest nesting of parentheses, and longest run of signs (- - x), accepted in an expression:
/// GiNaC's parser recurses on both and would exhaust the stack on hostile input.
constexpr int max_expression_nesting = 200;
/// Integer (or rational) exponents of non-constant bases beyond this are refused: (x+1)^99999 would take
/// minutes to differentiate and expand.
constexpr long max_power_exponent = 256;
/// Longest model name: it names the namespace, the files and the HAMEL_<NAME>_REAL macro of the package.
constexpr std::size_t max_model_name_length = 64;

/// The items of a comma-separated list whose items may be expressions: split at the commas outside parentheses
/// ("f=atan2(y,x),g=1" has two items).
std::vector<std::string> split_top_level(const std::string& list);

/// Parses `text` with the symbols of `table` only. Throws std::invalid_argument with GiNaC's message
/// (unknown symbol, syntax), or for nesting deeper than max_expression_nesting, on failure.
GiNaC::ex parse_expression(const std::string& text, const GiNaC::symtab& table);

/// The substance of a parse error parse_expression threw: GiNaC's messages carry C++ function names and a position
/// that is always 0:0 ("unknown name 'x'", "expected ')' or ',' in argument list, got: EOF").
std::string describe_parse_error(std::string msg);

/// Empty if every part of `e` can be emitted as C++ (real numbers, symbols, + - * / ^, Pi, Euler,
/// Catalan and the functions of emittable_functions()); otherwise a description of the first part
/// that cannot, e.g. "the function 'atan2' (2 arguments)" or "the complex number I".
std::string unsupported_part(const GiNaC::ex& e);

/// The functions an expression may call, each with one argument, comma-separated for messages.
const std::string& emittable_functions();

/// The exact rational with the shortest decimal spelling that reads back as `value` (0.1 → 1/10), so
/// that numbers from the command line or parameter defaults evaluate without binary rounding.
GiNaC::ex exact_number(double value);

/// True if `name` is a valid C++ identifier that is not a keyword or a reserved name of the tool.
bool is_valid_identifier(const std::string& name, std::string* why = nullptr);

/// True if `name` may also name the namespace (and files, and the macro prefix) of emitted code: a
/// valid identifier that is not `std`, `posix` or `main` and not a name that <cmath> or the compiler already
/// defines at global scope (floor, gamma, y0, exit, NAN, linux, ...; see cmath_global_names.inc).
bool is_valid_model_name(const std::string& name, std::string* why = nullptr);

}  // namespace hamel
