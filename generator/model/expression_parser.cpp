#include "model/expression_parser.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/operations.hpp"
#include "model/input_error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>

namespace hamel {

namespace {

bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Converts the digits of a decimal mantissa and exponent into "(num/den)" exactly.
std::string decimal_to_rational(const std::string& int_part, const std::string& frac_part, long exponent) {
  std::string digits = int_part + frac_part;
  long scale = static_cast<long>(frac_part.size()) - exponent;  // value = digits * 10^-scale
  std::size_t first = digits.find_first_not_of('0');
  digits = first == std::string::npos ? "0" : digits.substr(first);
  if (digits == "0") return "0";
  if (scale <= 0) return "(" + digits + std::string(static_cast<std::size_t>(-scale), '0') + ")";
  return "(" + digits + "/1" + std::string(static_cast<std::size_t>(scale), '0') + ")";
}

}  // namespace

std::string exact_decimals(const std::string& text) {
  std::string out;
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    const char c = text[i];
    const bool starts_number = (std::isdigit(static_cast<unsigned char>(c)) ||
                                (c == '.' && i + 1 < n && std::isdigit(static_cast<unsigned char>(text[i + 1])))) &&
                               (i == 0 || !is_ident_char(text[i - 1]));
    if (!starts_number) {
      out += c;
      ++i;
      continue;
    }
    const std::size_t start = i;
    std::string int_part, frac_part;
    while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) int_part += text[i++];
    bool decimal = false;
    if (i < n && text[i] == '.') {
      decimal = true;
      ++i;
      while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) frac_part += text[i++];
    }
    long exponent = 0;
    if (i < n && (text[i] == 'e' || text[i] == 'E')) {
      std::size_t j = i + 1;
      bool negative = false;
      if (j < n && (text[j] == '+' || text[j] == '-')) negative = text[j++] == '-';
      if (j < n && std::isdigit(static_cast<unsigned char>(text[j]))) {
        decimal = true;
        long e = 0;
        while (j < n && std::isdigit(static_cast<unsigned char>(text[j]))) {
          e = std::min(e * 10 + (text[j++] - '0'), 10 * max_decimal_exponent);  // saturate, never overflow
        }
        if (e > max_decimal_exponent)
          throw std::invalid_argument("the number " + quote(text.substr(start, j - start)) +
                                      " has an exponent beyond ±" + std::to_string(max_decimal_exponent));
        exponent = negative ? -e : e;
        i = j;
      }
    }
    out += decimal ? decimal_to_rational(int_part, frac_part, exponent) : int_part;
  }
  return out;
}

namespace {

// Input GiNaC's parser (1.8) cannot take: it recurses once per parenthesis and once per prefix sign,
// so nesting deeper than any model needs would exhaust the stack; and a call with no arguments such
// as "sin()" crashes it (found by tests/fuzz). Both are refused before parsing.
void check_structure(const std::string& text) {
  int depth = 0, signs = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '(') {
      const std::size_t next = text.find_first_not_of(" \t\n\r\f\v", i + 1);
      if (next != std::string::npos && text[next] == ')')
        throw std::invalid_argument("empty parentheses '()'; a function takes one argument, as in sin(x)");
    }
    if (c == '(' || c == '[' || c == '{') {
      if (++depth > max_expression_nesting)
        throw std::invalid_argument("parentheses nest deeper than " + std::to_string(max_expression_nesting));
    } else if (c == ')' || c == ']' || c == '}') {
      --depth;
    }
    if (c == '+' || c == '-') {
      if (++signs > max_expression_nesting)
        throw std::invalid_argument("more than " + std::to_string(max_expression_nesting) + " signs in a row");
    } else if (!std::isspace(static_cast<unsigned char>(c)) && c != '(') {
      signs = 0;
    }
  }
}

const std::set<std::string>& function_set() {
  static const std::set<std::string> names = [] {
    std::set<std::string> out;
    for (const Function& f : functions()) out.insert(f.name);
    return out;
  }();
  return names;
}

// Constants emitted code cannot hold (1e400 would print as HUGE_VAL, 1e-400 as 0) and integer powers of
// non-constant bases so high that expanding or differentiating them runs for minutes ((x+1)^99999) are input
// errors: docs/errors.md, "Limits".
void check_constants_and_powers(const GiNaC::ex& e) {
  for (auto it = e.preorder_begin(); it != e.preorder_end(); ++it) {
    if (GiNaC::is_a<GiNaC::numeric>(*it)) {
      const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(*it);
      const GiNaC::numeric re = n.real();
      const double d = re.to_double();
      if (!std::isfinite(d) || (d == 0 && !re.is_zero())) {
        std::ostringstream text;
        text << re;
        throw std::invalid_argument("the constant " + quote(text.str()) +
                                    " is beyond the range of a double (about 1e-308 to 1e308 in magnitude)");
      }
    } else if (GiNaC::is_a<GiNaC::power>(*it) && GiNaC::is_a<GiNaC::numeric>(it->op(1)) &&
               !GiNaC::is_a<GiNaC::numeric>(it->op(0))) {
      const GiNaC::numeric& k = GiNaC::ex_to<GiNaC::numeric>(it->op(1));
      if (k.is_real() && abs(k) > max_power_exponent) {
        std::ostringstream text;
        text << k;
        throw std::invalid_argument("the exponent " + quote(text.str()) + " is beyond ±" +
                                    std::to_string(max_power_exponent));
      }
    }
  }
}

}  // namespace

std::vector<std::string> split_top_level(const std::string& list) {
  std::vector<std::string> parts;
  int depth = 0;
  std::string cur;
  for (char c : list) {
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth == 0) {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(cur);
  return parts;
}

GiNaC::ex parse_expression(const std::string& text, const GiNaC::symtab& table) {
  check_structure(text);
  // Only the names the text uses: GiNaC's parser copies its table, and a table of every symbol of a large model
  // (10 000 definitions, a URDF chain of 10 000 links) made every parse, and so loading, linear in the model's size.
  // `pi` is accepted as well as GiNaC's `Pi` (both are reserved as names).
  const std::string exact = exact_decimals(text);
  GiNaC::symtab used;
  for (std::size_t i = 0; i < exact.size();) {
    const unsigned char c = static_cast<unsigned char>(exact[i]);
    if (std::isalpha(c) || c == '_') {
      std::size_t end = i + 1;
      while (end < exact.size() && (std::isalnum(static_cast<unsigned char>(exact[end])) || exact[end] == '_')) ++end;
      const std::string name = exact.substr(i, end - i);
      if (const auto it = table.find(name); it != table.end()) used.insert(*it);
      i = end;
    } else if (std::isdigit(c) || c == '.') {  // a number, with its exponent (1e5 names no symbol e5)
      auto digit = [&](std::size_t k) {
        return k < exact.size() && std::isdigit(static_cast<unsigned char>(exact[k]));
      };
      while (digit(i) || (i < exact.size() && exact[i] == '.')) ++i;
      if (i < exact.size() && (exact[i] == 'e' || exact[i] == 'E')) {
        const std::size_t k = i + 1 + (i + 1 < exact.size() && (exact[i + 1] == '+' || exact[i + 1] == '-'));
        if (digit(k)) {
          i = k;
          while (digit(i)) ++i;
        }
      }
    } else {
      ++i;
    }
  }
  used.emplace("pi", GiNaC::Pi);
  GiNaC::parser reader(used, /*strict=*/true);
  const GiNaC::ex parsed = reader(exact);
  check_constants_and_powers(parsed);
  return parsed;
}

const std::string& emittable_functions() {
  static const std::string list = [] {
    std::string s;
    for (const auto& f : function_set()) s += (s.empty() ? "" : ", ") + f;
    return s;
  }();
  return list;
}

std::string unsupported_part(const GiNaC::ex& e) {
  if (GiNaC::is_a<GiNaC::numeric>(e))
    return GiNaC::ex_to<GiNaC::numeric>(e).is_real() ? std::string() : "the complex number " + to_text(e);
  if (GiNaC::is_a<GiNaC::symbol>(e)) return {};
  if (GiNaC::is_a<GiNaC::constant>(e))
    return e.is_equal(GiNaC::Pi) || e.is_equal(GiNaC::Euler) || e.is_equal(GiNaC::Catalan)
               ? std::string()
               : "the constant " + to_text(e);
  if (GiNaC::is_a<GiNaC::function>(e)) {
    const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
    if (!function_set().count(name) || e.nops() != 1)
      return "the function '" + name + "' (" + std::to_string(e.nops()) +
             (e.nops() == 1 ? " argument)" : " arguments)");
  } else if (!GiNaC::is_a<GiNaC::add>(e) && !GiNaC::is_a<GiNaC::mul>(e) && !GiNaC::is_a<GiNaC::power>(e)) {
    return quote(to_text(e));
  }
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (std::string part = unsupported_part(e.op(i)); !part.empty()) return part;
  return {};
}

GiNaC::ex exact_number(double value) { return parse_expression(shortest_decimal(value), GiNaC::symtab()); }

bool is_valid_identifier(const std::string& name, std::string* why) {
  static const std::set<std::string> keywords = {
      "alignas",     "alignof",   "and",        "and_eq",    "asm",      "auto",         "bitand",
      "bitor",       "bool",      "break",      "case",      "catch",    "char",         "char8_t",
      "char16_t",    "char32_t",  "class",      "compl",     "concept",  "const",        "consteval",
      "constexpr",   "constinit", "const_cast", "continue",  "co_await", "co_return",    "co_yield",
      "decltype",    "default",   "delete",     "do",        "double",   "dynamic_cast", "else",
      "enum",        "explicit",  "export",     "extern",    "false",    "float",        "for",
      "friend",      "goto",      "if",         "inline",    "int",      "long",         "mutable",
      "namespace",   "new",       "noexcept",   "not",       "not_eq",   "nullptr",      "operator",
      "or",          "or_eq",     "private",    "protected", "public",   "register",     "reinterpret_cast",
      "requires",    "return",    "short",      "signed",    "sizeof",   "static",       "static_assert",
      "static_cast", "struct",    "switch",     "template",  "this",     "thread_local", "throw",
      "true",        "try",       "typedef",    "typeid",    "typename", "union",        "unsigned",
      "using",       "virtual",   "void",       "volatile",  "wchar_t",  "while",        "xor",
      "xor_eq"};
  // Names the expression language already uses (user names never reach emitted code: symbols are
  // read from the kernel's argument arrays by index).
  static const std::set<std::string> reserved = [] {
    std::set<std::string> out = function_set();
    out.insert({"t", "atan2", "pow", "Pi", "pi", "I", "Euler", "Catalan"});
    return out;
  }();
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (name.empty()) return fail("a name must not be empty");
  if (!(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_'))
    return fail(quote(name) + " is not a valid C++ identifier (it must start with a letter or '_')");
  for (char c : name)
    if (!is_ident_char(c)) return fail(quote(name) + " is not a valid C++ identifier (letters, digits and '_' only)");
  if (name[0] == '_') return fail(quote(name) + " starts with '_', which C++ reserves for the implementation");
  if (name.find("__") != std::string::npos) return fail(quote(name) + " contains '__', which C++ reserves");
  if (keywords.count(name)) return fail(quote(name) + " is a C++ keyword");
  if (reserved.count(name)) return fail(quote(name) + " is reserved (a function, constant or emitted-code name)");
  if (name.size() > 4 && name.compare(name.size() - 4, 4, "_dot") == 0)
    return fail(quote(name) + " ends in '_dot', which is reserved for coordinate rates");
  return true;
}

bool is_valid_model_name(const std::string& name, std::string* why) {
  if (!is_valid_identifier(name, why)) return false;
  static const std::set<std::string> taken = {
#include "model/cmath_global_names.inc"
      "std", "posix", "main",
      // Classification macros of <math.h> that glibc also declares as functions, and what <cstring>,
      // <cstddef> and <cstdint> put at global scope (the emitted code includes them): found by a package
      // named isnan or memcpy failing -Werror.
      "isnan", "isinf", "isfinite", "isnormal", "signbit", "fpclassify", "isgreater", "isless", "isunordered", "memcpy",
      "memmove", "memset", "memcmp", "memchr", "strlen", "strcpy", "strcmp", "size_t", "ptrdiff_t", "max_align_t",
      "nullptr_t", "int8_t", "int16_t", "int32_t", "int64_t", "uint8_t", "uint16_t", "uint32_t", "uint64_t", "intptr_t",
      "uintptr_t"};
  // File names and the HAMEL_<NAME>_REAL macro grow with the name: a 250-character name broke CMake's
  // configure and a 5000-character one the file system.
  if (name.size() > max_model_name_length) {
    if (why)
      *why = quote(name) + " has " + std::to_string(name.size()) + " characters, more than the limit of " +
             std::to_string(max_model_name_length);
    return false;
  }
  if (taken.count(name)) {
    if (why)
      *why = quote(name) +
             " is already defined at global scope by <cmath>, the C library or the compiler, and the "
             "emitted code includes <cmath>";
    return false;
  }
  return true;
}

std::string describe_parse_error(std::string msg) {
  const std::string unknown = "symbol \"";
  if (auto at = msg.find(unknown); at != std::string::npos && msg.find("not found") != std::string::npos) {
    const auto start = at + unknown.size();
    return "unknown name '" + msg.substr(start, msg.find('"', start) - start) + "'";
  }
  if (auto bracket = msg.find("\n["); bracket != std::string::npos) msg.erase(bracket);
  if (auto bracket = msg.find(" ["); bracket != std::string::npos) msg.erase(bracket);
  for (const std::string prefix : {"GiNaC: ", "parse error at line 0, column 0: "})
    if (auto at = msg.find(prefix); at != std::string::npos) msg.erase(at, prefix.size());
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
  return msg;
}

}  // namespace hamel
