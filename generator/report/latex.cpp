#include "report/latex.hpp"

#include "algebra/expression_text.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <sstream>
#include <utility>
#include <vector>

namespace hamel {

namespace {

bool is_greek(const std::string& s) {
  static const std::set<std::string> greek{
      "alpha", "beta",   "gamma",   "delta", "epsilon", "varepsilon", "zeta", "eta",   "theta", "vartheta",
      "iota",  "kappa",  "lambda",  "mu",    "nu",      "xi",         "pi",   "varpi", "rho",   "varrho",
      "sigma", "tau",    "upsilon", "phi",   "varphi",  "chi",        "psi",  "omega", "Gamma", "Delta",
      "Theta", "Lambda", "Xi",      "Pi",    "Sigma",   "Upsilon",    "Phi",  "Psi",   "Omega", "varsigma"};
  return greek.count(s) > 0;
}

bool all_of(const std::string& s, int (*pred)(int)) {
  if (s.empty()) return false;
  for (unsigned char c : s)
    if (!pred(c)) return false;
  return true;
}

// One part of a name without digits or with only digits: x, psi, locked, 12.
std::string atom(const std::string& s) {
  if (all_of(s, ::isdigit)) return s;
  if (is_greek(s)) return "\\" + s;
  if (s.size() == 1) return s;
  return "\\mathrm{" + s + "}";
}

std::string typewriter(const std::string& name) {
  std::string out = "\\mathtt{";
  for (char c : name) {
    if (c == '_')
      out += "\\_";
    else if (std::isalnum(static_cast<unsigned char>(c)))
      out += c;
    else
      out += '?';
  }
  return out + "}";
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts(1);
  for (char c : s) {
    if (c == sep)
      parts.emplace_back();
    else
      parts.back() += c;
  }
  return parts;
}

}  // namespace

std::string latex_name(const std::string& name) {
  std::size_t lead = 0;
  while (lead < name.size() && name[lead] == '_') ++lead;
  std::string rest = name.substr(lead);
  bool dot = false;
  if (rest.size() > 4 && rest.compare(rest.size() - 4, 4, "_dot") == 0) {
    dot = true;
    rest.resize(rest.size() - 4);
  }
  std::vector<std::string> parts = split(rest, '_');
  for (const std::string& p : parts)
    if (!all_of(p, ::isalnum)) return typewriter(name);
  std::string base;
  std::vector<std::string> sub;
  if (lead > 0) {  // an intermediate symbol: s with the rest of the name as index
    base = "\\mathrm{s}";
    for (const std::string& p : parts)
      sub.push_back(all_of(p, ::isdigit) || is_greek(p) ? atom(p) : "\\mathrm{" + p + "}");
  } else {
    // The head: letters, optionally followed by digits that become the first index (theta1, m2, R00).
    const std::string& head = parts[0];
    std::size_t letters = 0;
    while (letters < head.size() && std::isalpha(static_cast<unsigned char>(head[letters]))) ++letters;
    const std::string digits = head.substr(letters);
    if (letters == 0) return typewriter(name);
    const std::string word = head.substr(0, letters);
    const char last = word.back();
    const std::string stem = word.substr(0, letters - 1);
    if (digits.empty() && letters >= 2 && (last == 'x' || last == 'y' || last == 'z') &&
        (stem.size() == 1 || is_greek(stem))) {
      base = atom(stem);  // a component: vx, wz, omegax
      sub.push_back(std::string(1, last));
    } else if (digits.empty() || all_of(digits, ::isdigit)) {
      base = atom(word);
      if (!digits.empty()) sub.push_back(digits);
    } else {
      base = "\\mathrm{" + head + "}";  // letters, digits and letters again: w2x
    }
    for (std::size_t k = 1; k < parts.size(); ++k)
      sub.push_back(all_of(parts[k], ::isdigit) || is_greek(parts[k]) || parts[k].size() == 1
                        ? atom(parts[k])
                        : "\\mathrm{" + parts[k] + "}");
  }
  if (dot) base = "\\dot{" + base + "}";
  std::string out = base;
  if (!sub.empty()) {
    out += "_{";
    for (std::size_t k = 0; k < sub.size(); ++k) out += (k ? "," : "") + sub[k];
    out += "}";
  }
  return out;
}

/// The floating-point literals CLN prints, as (position, length): the matches, left to right and not
/// overlapping, of [0-9]+\.[0-9]*(E[-+]?[0-9]+)?.
std::vector<std::pair<std::size_t, std::size_t>> float_literals(const std::string& s) {
  std::vector<std::pair<std::size_t, std::size_t>> found;
  const auto digit = [&s](std::size_t i) { return i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); };
  std::size_t i = 0;
  while (i < s.size()) {
    if (!digit(i)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (digit(j)) ++j;
    if (j >= s.size() || s[j] != '.') {  // an integer: no literal starts inside it
      i = j;
      continue;
    }
    ++j;
    while (digit(j)) ++j;
    if (j < s.size() && s[j] == 'E') {
      std::size_t k = j + 1;
      if (k < s.size() && (s[k] == '-' || s[k] == '+')) ++k;
      if (digit(k)) {
        while (digit(k)) ++k;
        j = k;
      }
    }
    found.emplace_back(i, j - i);
    i = j;
  }
  return found;
}

std::string latex_text(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '\\':
        out += "\\textbackslash{}";
        break;
      case '{':
        out += "\\{";
        break;
      case '}':
        out += "\\}";
        break;
      case '_':
        out += "\\_";
        break;
      case '#':
        out += "\\#";
        break;
      case '%':
        out += "\\%";
        break;
      case '&':
        out += "\\&";
        break;
      case '$':
        out += "\\$";
        break;
      case '^':
        out += "\\textasciicircum{}";
        break;
      case '~':
        out += "\\textasciitilde{}";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f) out += c;
    }
  }
  return out;
}

const std::string& LatexPrinter::name(const std::string& name) {
  auto it = tex_.find(name);
  if (it != tex_.end()) return it->second;
  std::string tex = latex_name(name);
  if (spelled_.count(tex)) tex = typewriter(name);
  spelled_.insert(tex);
  return tex_.emplace(name, tex).first->second;
}

std::string LatexPrinter::expr(const GiNaC::ex& e) {
  const std::string s = to_latex(e, [this](const std::string& symbol) { return name(symbol); });
  // Floats (CLN writes 0.2999999999999999889 and 1.4999999999999999321E-7) as their shortest decimal, the
  // exponent as \cdot 10^{k}; spaces collapsed (insignificant in math mode).
  std::string floats;
  std::size_t done = 0;
  for (const auto& [at, length] : float_literals(s)) {
    if (at > 0 && (std::isalnum(static_cast<unsigned char>(s[at - 1])) || s[at - 1] == '.')) continue;
    std::string literal = s.substr(at, length);
    std::replace(literal.begin(), literal.end(), 'E', 'e');
    std::string shortest = shortest_decimal(std::strtod(literal.c_str(), nullptr));
    const std::size_t e = shortest.find('e');
    if (e != std::string::npos) {
      const int exponent = std::atoi(shortest.c_str() + e + 1);
      shortest = shortest.substr(0, e) + " \\cdot 10^{" + std::to_string(exponent) + "}";
    }
    floats += s.substr(done, at - done) + shortest;
    done = at + length;
  }
  floats += s.substr(done);
  std::string out;
  for (char c : floats) {
    if (c == ' ' && (out.empty() || out.back() == ' ' || out.back() == '{' || out.back() == '(')) continue;
    if ((c == '}' || c == ')') && !out.empty() && out.back() == ' ') out.pop_back();
    out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace hamel
