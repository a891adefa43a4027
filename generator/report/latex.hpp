// LaTeX for reports (`hamel derive --latex`): symbol names as math-mode TeX, expressions in GiNaC's LaTeX notation
// with those names (in structural order, algebra/expression_text.hpp), and text escaped for text mode.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <set>
#include <string>

namespace hamel {

/// Math-mode TeX for an identifier, e.g. theta1 → \theta_{1}, u_x → u_{x}, w_psi → w_{\psi},
/// psi_dot → \dot{\psi}, wx_locked → \mathrm{wx}_{\mathrm{locked}}; intermediate symbols (a leading '_':
/// _12, _disk_w0) → \mathrm{s}_{12}, \mathrm{s}_{\mathrm{disk},\mathrm{w0}}. Names the rules do not cover
/// become \mathtt{...} with underscores escaped.
std::string latex_name(const std::string& name);

/// `s` for LaTeX text mode: the ten special characters escaped, control characters dropped.
std::string latex_text(const std::string& s);

/// Prints names and expressions with one TeX spelling per symbol name; when two names would print alike
/// (theta1 and theta_1), the later one is spelled \mathtt{theta\_1}.
class LatexPrinter {
 public:
  /// Math-mode TeX of the symbol called `name`.
  const std::string& name(const std::string& name);
  /// Math-mode TeX of `e` (algebra/expression_text.hpp's to_latex: GiNaC's notation in structural order; floats as
  /// m \cdot 10^{k}).
  std::string expr(const GiNaC::ex& e);

 private:
  std::map<std::string, std::string> tex_;  // symbol name → TeX
  std::set<std::string> spelled_;           // TeX spellings in use
};

}  // namespace hamel
