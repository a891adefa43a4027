// `hamel derive --latex`: the fragment is well-formed LaTeX for shipped models (balanced braces, environments and
// \left/\right; no raw _ ^ & # % $ outside their places; intermediate and underscored names spelled as TeX), and
// compiles with pdflatex when pdflatex is installed. Also the TeX spelling of names, and --latex's refusals.
#include "report/latex.hpp"

#include "support/command.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using hamel::test::Outcome;
using hamel::test::run;
using hamel::test::slurp;
using hamel::test::source;

Outcome hamel(const std::string& args) { return run(std::string(HAMEL_BINARY) + " " + args); }

bool escaped(const std::string& s, std::size_t k) {
  std::size_t backslashes = 0;
  while (k > backslashes && s[k - 1 - backslashes] == '\\') ++backslashes;
  return backslashes % 2 == 1;
}

// Index of the brace closing the group that opens at s[open] == '{', or npos.
std::size_t closing(const std::string& s, std::size_t open) {
  int depth = 0;
  for (std::size_t k = open; k < s.size(); ++k) {
    if (escaped(s, k)) continue;
    if (s[k] == '{') ++depth;
    if (s[k] == '}' && --depth == 0) return k;
  }
  return std::string::npos;
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

// The markup checks; an empty list when the fragment is well-formed.
std::vector<std::string> markup_problems(const std::string& tex) {
  std::vector<std::string> problems;
  // Comments only as whole lines (the header); nothing after them is checked.
  std::string body;
  std::size_t line_start = 0;
  while (line_start < tex.size()) {
    std::size_t end = tex.find('\n', line_start);
    if (end == std::string::npos) end = tex.size();
    const std::string line = tex.substr(line_start, end - line_start);
    if (line.rfind("%", 0) != 0) body += line + "\n";
    line_start = end + 1;
  }
  // Environments nest, and only align* is used.
  for (std::size_t at = 0; (at = body.find("\\begin{", at)) != std::string::npos; ++at) {
    const std::size_t end = body.find('}', at);
    if (body.substr(at + 7, end - at - 7) != "align*") problems.push_back("environment other than align*");
  }
  if (count(body, "\\begin{align*}") != count(body, "\\end{align*}")) problems.push_back("unbalanced align*");
  // \left and \right pair up (not \leftarrow and the like).
  std::size_t left = 0, right = 0;
  for (std::size_t k = 0; k + 6 <= body.size(); ++k) {
    if (body.compare(k, 5, "\\left") == 0 && !std::isalpha(static_cast<unsigned char>(body[k + 5]))) ++left;
    if (body.compare(k, 6, "\\right") == 0 &&
        (k + 6 == body.size() || !std::isalpha(static_cast<unsigned char>(body[k + 6]))))
      ++right;
  }
  if (left != right) problems.push_back("\\left/\\right unbalanced");
  // Braces balanced; mode tracked: text, inline math ($...$) or an align* row.
  int depth = 0;
  bool inline_math = false, display = false;
  std::size_t ampersands_in_row = 0;
  for (std::size_t k = 0; k < body.size(); ++k) {
    const char c = body[k];
    if (body.compare(k, 14, "\\begin{align*}") == 0) {
      if (display || inline_math) problems.push_back("align* inside math");
      display = true;
      ampersands_in_row = 0;
      k += 13;
      continue;
    }
    if (body.compare(k, 12, "\\end{align*}") == 0) {
      if (!display) problems.push_back("\\end{align*} outside align*");
      if (ampersands_in_row != 1) problems.push_back("align* row without exactly one &");
      display = false;
      k += 11;
      continue;
    }
    if (escaped(body, k)) continue;
    const bool math = inline_math || display;
    switch (c) {
      case '{':
        ++depth;
        break;
      case '}':
        if (--depth < 0) problems.push_back("} without {");
        break;
      case '$':
        if (display) problems.push_back("$ inside align*");
        inline_math = !inline_math;
        break;
      case '#':
        problems.push_back("raw #");
        break;
      case '%':
        problems.push_back("raw % inside the body");
        break;
      case '&':
        if (!display) problems.push_back("& outside align*");
        ++ampersands_in_row;
        break;
      case '\\':
        if (display && k + 1 < body.size() && body[k + 1] == '\\') {
          if (ampersands_in_row != 1) problems.push_back("align* row without exactly one &");
          ampersands_in_row = 0;
          ++k;
        }
        break;
      case '_':
      case '^': {
        if (!math) {
          problems.push_back(std::string("raw ") + c + " outside math near: " + body.substr(k > 30 ? k - 30 : 0, 60));
          break;
        }
        // Every sub- and superscript of ours is braced, and none is doubled (x_{1}_{2}, x^{2}^{3}).
        if (k + 1 >= body.size() || body[k + 1] != '{') break;  // GiNaC's own \gamma_E
        const std::size_t end = closing(body, k + 1);
        if (end == std::string::npos) {
          problems.push_back("unclosed index group");
          break;
        }
        if (end + 1 < body.size() && body[end + 1] == c)
          problems.push_back(std::string("double ") + c + " near: " + body.substr(k > 30 ? k - 30 : 0, 80));
        break;
      }
      default:
        break;
    }
    if (c == '\n' && inline_math) problems.push_back("inline math across a line");
  }
  if (depth != 0) problems.push_back("unbalanced braces");
  if (inline_math || display) problems.push_back("math not closed");
  return problems;
}

bool have_pdflatex() { return std::system("command -v pdflatex >/dev/null 2>&1") == 0; }

// Wraps `fragment` in a minimal document and runs pdflatex on it; empty when it compiles, else the log's tail.
std::string compile(const std::string& name, const std::string& fragment) {
  const fs::path dir = fs::temp_directory_path() / ("hamel_latex_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "fragment.tex") << fragment;
  std::ofstream(dir / "doc.tex") << "\\documentclass{article}\n\\usepackage{amsmath}\n\\begin{document}\n"
                                    "\\input{fragment}\n\\end{document}\n";
  const Outcome r = run("cd '" + dir.string() +
                        "' && pdflatex -interaction=nonstopmode -halt-on-error doc.tex > pdflatex.out 2>&1; "
                        "echo $?; tail -n 30 pdflatex.out");
  if (r.out.rfind("0\n", 0) == 0 && fs::exists(dir / "doc.pdf")) {
    fs::remove_all(dir);
    return {};
  }
  return r.out;
}

class DeriveLatex : public ::testing::TestWithParam<const char*> {};

TEST_P(DeriveLatex, FragmentIsWellFormedAndCompiles) {
  const std::string model = GetParam();
  const Outcome r = hamel("derive " + source("models/" + model + ".yaml") + " --latex 2>/dev/null");
  ASSERT_EQ(r.status, 0);
  ASSERT_FALSE(r.out.empty());
  for (const std::string& p : markup_problems(r.out)) ADD_FAILURE() << model << ": " << p;
  EXPECT_NE(r.out.find("\\gamma^{"), std::string::npos) << "Hamel coefficients section";
  EXPECT_NE(r.out.find("M_{"), std::string::npos);
  EXPECT_NE(r.out.find("f_{"), std::string::npos);
  if (!have_pdflatex()) {
    std::cout << "pdflatex not installed: markup checked, not compiled\n";
    return;
  }
  const std::string log = compile(model, r.out);
  EXPECT_TRUE(log.empty()) << model << ": pdflatex failed:\n" << log;
}

INSTANTIATE_TEST_SUITE_P(ShippedModels, DeriveLatex,
                         ::testing::Values("rolling_ball", "double_pendulum", "rolling_disk_routh", "falling_cat",
                                           "satellite_se3_tree", "chaplygin_sleigh"));

TEST(DeriveLatexContent, NotationOfThePaper) {
  const Outcome ball = hamel("derive " + source("models/rolling_ball.yaml") + " --latex 2>/dev/null");
  ASSERT_EQ(ball.status, 0);
  // gamma^{u3}_{vx,vy} = -1/R^2 (eq. gammaNH), starred; B^{x}_{vx} = 1; intermediates as s_k in a "where" list.
  EXPECT_NE(ball.out.find("\\star\\ \\gamma^{u_{3}}_{v_{x},v_{y}} &= -\\frac{1}{R^{2}}"), std::string::npos)
      << ball.out;
  EXPECT_NE(ball.out.find("B^{x}_{v_{x}} &= 1"), std::string::npos);
  EXPECT_NE(ball.out.find("\\paragraph{Where} (intermediate symbols"), std::string::npos);
  EXPECT_NE(ball.out.find("\\mathrm{s}_{1} &= "), std::string::npos);
  // Only one of each antisymmetric pair: gamma^{u3}_{vy,vx} is not listed.
  EXPECT_EQ(ball.out.find("\\gamma^{u_{3}}_{v_{y},v_{x}}"), std::string::npos);

  const Outcome disk = hamel("derive " + source("models/rolling_disk_routh.yaml") + " --latex 2>/dev/null");
  ASSERT_EQ(disk.status, 0);
  EXPECT_NE(disk.out.find("\\gamma^{u_{x}}_{w_{\\psi},w_{\\phi}}"), std::string::npos);
  EXPECT_NE(disk.out.find("\\mathrm{s}_{\\mathrm{disk},\\mathrm{R00}} &= "), std::string::npos);  // _disk_R00

  const Outcome cat = hamel("derive " + source("models/falling_cat.yaml") + " --latex 2>/dev/null");
  ASSERT_EQ(cat.status, 0);
  EXPECT_NE(cat.out.find("\\mathcal{A}^{w_{x}}_{\\psi} &= "), std::string::npos);
  EXPECT_NE(cat.out.find("\\mathcal{B}^{w_{x}}_{\\psi,\\theta} &= "), std::string::npos);
  EXPECT_NE(cat.out.find("c^{w_{x}}_{w_{y},w_{z}} &= 1"), std::string::npos);
  EXPECT_NE(cat.out.find("\\dot{\\psi}"), std::string::npos);  // the shape rate psi_dot

  const Outcome pendulum = hamel("derive " + source("models/double_pendulum.yaml") + " --latex 2>/dev/null");
  ASSERT_EQ(pendulum.status, 0);
  EXPECT_NE(pendulum.out.find("\\dot{\\theta}_{1} &= \\omega_{1}"), std::string::npos) << pendulum.out;
  EXPECT_NE(pendulum.out.find("none: the quasi-velocities are holonomic."), std::string::npos);
}

TEST(DeriveLatexContent, TextAndJsonAreUnchangedByTheOption) {
  // --latex is a separate output: it cannot be combined with --json, --riemann or --at (exit 2, nothing on stdout).
  for (const char* other : {"--json", "--riemann", "--at theta1=0.1"}) {
    const Outcome r = hamel("derive " + source("models/double_pendulum.yaml") + " --latex " + other + " 2>/dev/null");
    EXPECT_EQ(r.status, 2) << other;
    EXPECT_TRUE(r.out.empty()) << other;
  }
  const Outcome text = hamel("derive " + source("models/double_pendulum.yaml") + " 2>/dev/null");
  ASSERT_EQ(text.status, 0);
  EXPECT_EQ(text.out.find("\\"), std::string::npos);  // plain text, as before
}

TEST(DeriveLatexContent, MarkupCheckFindsFaults) {
  EXPECT_TRUE(markup_problems("text $x_{1}$ and \\begin{align*}\n a &= b \\\\\n c &= d\n\\end{align*}\n").empty());
  for (const char* bad : {"a_b", "$x_{1}_{2}$", "${x$", "$x$}", "\\begin{align*}\n a = b\n\\end{align*}\n", "$a & b$",
                          "50% off", "$\\left( x$", "$x$ #1", "\\begin{align*}\n a &= b\n"})
    EXPECT_FALSE(markup_problems(bad).empty()) << bad;
}

TEST(LatexName, SpellsIdentifiersAsTeX) {
  using hamel::latex_name;
  EXPECT_EQ(latex_name("x"), "x");
  EXPECT_EQ(latex_name("theta1"), "\\theta_{1}");
  EXPECT_EQ(latex_name("u_x"), "u_{x}");
  EXPECT_EQ(latex_name("w_psi"), "w_{\\psi}");
  EXPECT_EQ(latex_name("psi_dot"), "\\dot{\\psi}");
  EXPECT_EQ(latex_name("theta1_dot"), "\\dot{\\theta}_{1}");
  EXPECT_EQ(latex_name("wx_locked"), "w_{x,\\mathrm{locked}}");
  EXPECT_EQ(latex_name("vx"), "v_{x}");
  EXPECT_EQ(latex_name("omegaz"), "\\omega_{z}");
  EXPECT_EQ(latex_name("max"), "\\mathrm{max}");
  EXPECT_EQ(latex_name("R00"), "R_{00}");
  EXPECT_EQ(latex_name("w2x"), "\\mathrm{w2x}");
  EXPECT_EQ(latex_name("Omega"), "\\Omega");
  EXPECT_EQ(latex_name("_12"), "\\mathrm{s}_{12}");
  EXPECT_EQ(latex_name("_disk_w0"), "\\mathrm{s}_{\\mathrm{disk},\\mathrm{w0}}");
  EXPECT_EQ(latex_name("a__b"), "\\mathtt{a\\_\\_b}");  // no rule: typewriter, underscores escaped
  hamel::LatexPrinter p;
  EXPECT_EQ(p.name("theta1"), "\\theta_{1}");
  EXPECT_EQ(p.name("theta_1"), "\\mathtt{theta\\_1}");  // would print like theta1
  EXPECT_EQ(p.name("theta1"), "\\theta_{1}");
  const GiNaC::realsymbol x("_3"), y("u_x");
  EXPECT_EQ(p.expr(x), "\\mathrm{s}_{3}");
  EXPECT_EQ(p.expr(GiNaC::pow(y, 2)), "u_{x}^{2}");
  EXPECT_EQ(p.expr(GiNaC::numeric(1.5e-7) * y), "{(1.5 \\cdot 10^{-7})} u_{x}");
  EXPECT_EQ(hamel::latex_text("a_b#c%d&e$f{g}\\h^i~j"),
            "a\\_b\\#c\\%d\\&e\\$f\\{g\\}\\textbackslash{}h\\textasciicircum{}i\\textasciitilde{}j");
}

}  // namespace
