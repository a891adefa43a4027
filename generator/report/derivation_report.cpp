#include "report/derivation_report.hpp"

#include "algebra/contract_trig.hpp"
#include "algebra/expression_text.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"
#include "report/latex.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <utility>

namespace hamel {

GiNaC::ex ExpressionDisplay::operator()(const GiNaC::ex& e) const {
  constexpr std::size_t inline_limit = 20000;
  std::optional<GiNaC::ex> shown;
  if (inline_through) shown = inline_through->inline_bounded(e, inline_limit);
  return contract_trig(shown ? simplify_bounded(*shown) : e);
}

namespace {

// How an entry shows an expression: its text, and its value where it has one.
struct Shown {
  const ExpressionDisplay& display;
  const ValueOf& value;
};

nlohmann::json entry(const GiNaC::ex& e, const Shown& values) {
  nlohmann::json j;
  j["expr"] = to_text(values.display(e));
  if (auto v = values.value(e)) j["value"] = *v;
  return j;
}

nlohmann::json matrix_json(const GiNaC::matrix& m, unsigned rows, unsigned cols,
                           const std::vector<std::string>& row_names, const std::vector<std::string>& col_names,
                           const Shown& values) {
  nlohmann::json out = nlohmann::json::array();
  for (unsigned r = 0; r < rows; ++r)
    for (unsigned c = 0; c < cols; ++c) {
      nlohmann::json e = entry(m(r, c), values);
      e["row"] = row_names[r];
      e["col"] = col_names[c];
      out.push_back(e);
    }
  return out;
}

// The bundle quantities of Sec. 3–5: group, structure constants, connection, curvature, E, L and M^Ω.
void add_bundle_json(nlohmann::json& j, const Model& model, const Derivation& d, const Shown& values,
                     CurvatureSign sign) {
  const Bundle& b = *model.bundle;
  const BundleGeometry& g = *d.bundle;
  const unsigned m = g.algebra.dim();
  const unsigned n = static_cast<unsigned>(model.coordinates.size());
  std::vector<std::string> xi, r;
  for (const auto& s : b.group_velocity) xi.push_back(s.get_name());
  for (const auto& s : model.coordinates) r.push_back(s.get_name());
  j["form"] = form_name(*d.form);
  j["group"] = {{"name", b.group},
                {"trivialization", b.right ? "right" : "left"},
                {"basis", g.algebra.basis_names},
                {"velocity", xi},
                {"connection", b.nonholonomic ? "nonholonomic"
                               : b.mechanical ? "mechanical"
                                              : "kinematic"}};
  if (!b.bodies.empty()) j["group"]["bodies"] = b.bodies;
  j["structure_constants"] = nlohmann::json::array();
  for (const StructureConstant& c : g.structure_constants) {
    nlohmann::json e = entry(c.value, values);
    e["alpha"] = xi[static_cast<std::size_t>(c.upper)];
    e["beta"] = xi[static_cast<std::size_t>(c.lower_a)];
    e["lambda"] = xi[static_cast<std::size_t>(c.lower_b)];
    j["structure_constants"].push_back(e);
  }
  if (b.tree) {
    j["group"]["tree"] = tree_body_names(*b.tree);
  }
  j["connection"] = nlohmann::json::array();
  if (!g.connection_derived)
    j["connection_note"] =
        "kinematic tree: A = L^-1 K is not formed symbolically; the connection and shape_inertia kernels solve "
        "L A = K numerically (L and K are blocks of the mass matrix). Use --form lp or momentum on small trees "
        "for A, the curvature and E as expressions.";
  for (unsigned a = 0; a < m && g.connection_derived; ++a)
    for (unsigned I = 0; I < n; ++I) {
      nlohmann::json e = entry(g.connection(a, I), values);
      e["alpha"] = xi[a];
      e["I"] = r[I];
      j["connection"].push_back(e);
    }
  j["curvature_sign"] = sign == CurvatureSign::paper ? "paper (B = gamma)" : "gauge (B = -gamma)";
  j["curvature"] = nlohmann::json::array();
  for (const BundleCoefficient& c : g.curvature_in(sign)) {
    nlohmann::json e = entry(c.value, values);
    e["alpha"] = xi[static_cast<std::size_t>(c.upper)];
    e["I"] = r[static_cast<std::size_t>(c.lower_a)];
    e["J"] = r[static_cast<std::size_t>(c.lower_b)];
    j["curvature"].push_back(e);
  }
  j["E"] = nlohmann::json::array();
  for (const BundleCoefficient& c : g.E) {
    nlohmann::json e = entry(c.value, values);
    e["alpha"] = xi[static_cast<std::size_t>(c.upper)];
    e["beta"] = xi[static_cast<std::size_t>(c.lower_a)];
    e["I"] = r[static_cast<std::size_t>(c.lower_b)];
    j["E"].push_back(e);
  }
  for (unsigned a = 0; a < m; ++a) {
    nlohmann::json e = entry(d.group_velocity[a], values);
    e["row"] = xi[a];
    j["reconstruction"].push_back(e);
  }
  if (g.nonholonomic) {  // BKMM 1996: the sections of S = D ∩ V, the parts of the connection, the momentum equation
    const NonholonomicConnection& nh = *g.nonholonomic;
    const unsigned s = static_cast<unsigned>(b.momentum_velocities.size());
    std::vector<std::string> names, constraints;
    for (const auto& v : b.momentum_velocities) names.push_back(v.get_name());
    for (const auto& c : b.constraint_velocities) constraints.push_back(c.get_name());
    nlohmann::json h;
    h["constraints"] = constraints;
    h["solved_for"] = nlohmann::json::array();
    for (int a : nh.solved) h["solved_for"].push_back(xi[static_cast<std::size_t>(a)]);
    h["sections"] = matrix_json(nh.sections, m, s, xi, names, values);
    h["kinematic_connection"] = matrix_json(nh.kinematic, m, n, xi, r, values);
    h["locked_inertia"] = matrix_json(nh.locked_inertia, s, s, names, names, values);
    h["momentum"] = nlohmann::json::array();
    for (unsigned k = 0; k < s && d.momentum_equation; ++k) {
      nlohmann::json e;
      e["name"] = d.momentum_equation->momenta[k].get_name();
      e["velocity"] = names[k];
      e["momentum"] = entry(d.momentum_equation->momentum[k], values);
      e["rate"] = entry(d.momentum_equation->rate[k], values);
      h["momentum"].push_back(e);
    }
    j["nonholonomic"] = h;
  }
  if (g.quadratic) j["locked_inertia"] = matrix_json(g.L, m, m, xi, xi, values);
  if (b.mechanical && g.connection_derived) {
    nlohmann::json blocks;
    blocks["locked"] = j["locked_inertia"];
    if (n > 0) {
      blocks["shape"] = matrix_json(g.shape_inertia, n, n, r, r, values);
      // K − L A: zero by construction of A = L⁻¹K (the inertial decoupling of eq. MOmega).
      GiNaC::matrix off(m, n);
      for (unsigned a = 0; a < m; ++a)
        for (unsigned I = 0; I < n; ++I) {
          GiNaC::ex e = g.K(a, I);
          for (unsigned c = 0; c < m; ++c) e -= g.L(a, c) * g.connection(c, I);
          off(a, I) = shown_zero(e, d.equations.intermediates) ? GiNaC::ex(0) : simplify_bounded(e);
        }
      blocks["off_diagonal"] = matrix_json(off, m, n, xi, r, values);
    }
    j["M_Omega"] = blocks;
  }
}

// The Riemannian view (derive/riemann.hpp): metric, Christoffel symbols, curvature, covariant linearization.
// `program` extends the equations' intermediates by `first_new` onwards: those are listed here.
nlohmann::json riemann_json(const RiemannGeometry& r, const Intermediates& program, std::size_t first_new,
                            const Shown& values) {
  std::vector<std::string> q;
  for (const auto& s : r.coordinates) q.push_back(s.get_name());
  const unsigned n = static_cast<unsigned>(q.size());
  nlohmann::json j;
  j["convention"] =
      "L = 1/2 g_ab q_dot^a q_dot^b - V; Gamma_a,bc = 1/2 (d_b g_ac + d_c g_ab - d_a g_bc), Gamma^a_bc = g^ad "
      "Gamma_d,bc; R^a_bcd = d_c Gamma^a_db - d_d Gamma^a_cb + Gamma^a_ce Gamma^e_db - Gamma^a_de Gamma^e_cb, R_abcd "
      "= g_ae R^e_bcd; g_ab D2x^b/dt2 + K_ab x^b = Phi_a, K_ab = R_cbda q_dot^c q_dot^d - nabla_b Q_a, D x^a/dt = "
      "x_dot^a + G^a_c x^c";
  j["metric"] = matrix_json(r.metric, n, n, q, q, values);
  j["potential"] = entry(r.potential, values);
  for (unsigned a = 0; a < n; ++a) {
    nlohmann::json e = entry(r.forces[a], values);
    e["row"] = q[a];
    j["forces"].push_back(e);
  }
  j["christoffel_first_kind"] = nlohmann::json::array();
  for (const ChristoffelSymbol& c : r.first_kind) {
    nlohmann::json e = entry(c.value, values);
    e["index"] = q[static_cast<std::size_t>(c.index)];
    e["lower"] = {q[static_cast<std::size_t>(c.b)], q[static_cast<std::size_t>(c.c)]};
    j["christoffel_first_kind"].push_back(e);
  }
  j["christoffel"] = nlohmann::json::array();
  for (const ChristoffelSymbol& c : r.second_kind) {
    nlohmann::json e = entry(c.value, values);
    e["upper"] = q[static_cast<std::size_t>(c.index)];
    e["lower"] = {q[static_cast<std::size_t>(c.b)], q[static_cast<std::size_t>(c.c)]};
    j["christoffel"].push_back(e);
  }
  j["curvature"] = nlohmann::json::array();
  for (const CurvatureComponent& c : r.curvature) {
    nlohmann::json e = entry(c.value, values);
    e["indices"] = {q[static_cast<std::size_t>(c.a)], q[static_cast<std::size_t>(c.b)],
                    q[static_cast<std::size_t>(c.c)], q[static_cast<std::size_t>(c.d)]};
    j["curvature"].push_back(e);
  }
  j["flat"] = r.curvature.empty();
  j["connection_rate"] = matrix_json(r.connection_rate, n, n, q, q, values);
  j["force_gradient"] = matrix_json(r.force_gradient, n, n, q, q, values);
  j["stiffness"] = matrix_json(r.stiffness, n, n, q, q, values);
  j["intermediates"] = nlohmann::json::array();
  for (std::size_t k = first_new; k < program.size(); ++k) {
    nlohmann::json e = entry(program.definitions()[k].value, values);
    e["name"] = program.definitions()[k].symbol.get_name();
    j["intermediates"].push_back(e);
  }
  return j;
}

void print_riemann(std::ostream& out, const nlohmann::json& r,
                   const std::function<std::string(const nlohmann::json&)>& show) {
  const auto name = [](const nlohmann::json& s) { return s.get<std::string>(); };
  out << "\nRiemannian view (paper, Remark on Classical Riemannian Geometry Formulations), "
         "L = 1/2 g_ab q_dot^a q_dot^b - V:\n  metric g_ab = d2L/dq_dot^a dq_dot^b:\n";
  for (const auto& e : r["metric"])
    out << "    g[" << name(e["row"]) << "][" << name(e["col"]) << "] = " << show(e) << "\n";
  out << "  potential V = " << show(r["potential"]) << "\n";
  out << "  Christoffel symbols Gamma^a_bc (second kind), non-zero, b <= c:\n";
  if (r["christoffel"].empty()) out << "    none\n";
  for (const auto& e : r["christoffel"])
    out << "    Gamma^" << name(e["upper"]) << "_(" << name(e["lower"][0]) << "," << name(e["lower"][1])
        << ") = " << show(e) << "\n";
  out << "  Christoffel symbols Gamma_a,bc (first kind), non-zero, b <= c:\n";
  if (r["christoffel_first_kind"].empty()) out << "    none\n";
  for (const auto& e : r["christoffel_first_kind"])
    out << "    Gamma_" << name(e["index"]) << ",(" << name(e["lower"][0]) << "," << name(e["lower"][1])
        << ") = " << show(e) << "\n";
  out << "  Riemann-Christoffel tensor R_abcd, non-zero components with a < b, c < d, (a,b) <= (c,d):\n";
  if (r["curvature"].empty()) out << "    none: the metric is flat\n";
  for (const auto& e : r["curvature"])
    out << "    R_(" << name(e["indices"][0]) << "," << name(e["indices"][1]) << "," << name(e["indices"][2]) << ","
        << name(e["indices"][3]) << ") = " << show(e) << "\n";
  out << "  covariant linearization g_ab D2x^b/dt2 + K_ab x^b = Phi_a, D x^a/dt = x_dot^a + G^a_c x^c:\n";
  for (const auto& e : r["connection_rate"])
    if (e["expr"] != "0") out << "    G[" << name(e["row"]) << "][" << name(e["col"]) << "] = " << show(e) << "\n";
  for (const auto& e : r["stiffness"])
    out << "    K[" << name(e["row"]) << "][" << name(e["col"]) << "] = " << show(e) << "\n";
  if (!r["intermediates"].empty())
    out << "  intermediate symbols of the Riemannian quantities, in evaluation order (" << r["intermediates"].size()
        << "):\n";
  for (const auto& e : r["intermediates"]) out << "    " << name(e["name"]) << " = " << show(e) << "\n";
}

// `derive --latex`: the text output's quantities as a LaTeX fragment in the paper's notation, section by section.
class LatexWriter {
 public:
  LatexWriter(std::ostream& out, const Model& model, const Derivation& d, const ExpressionDisplay& display)
      : out(out), model(model), d(d), sys(d.system), eq(d.equations), display(display) {
    for (std::size_t a = 0; a < sys.coordinates.size(); ++a) qs.push_back(q(a));
    for (std::size_t a = 0; a < sys.velocities.size(); ++a) us.push_back(u(static_cast<int>(a)));
  }

  void write(CurvatureSign sign) {
    header();
    if (d.bundle)
      bundle(sign);
    else
      quasi_velocities();
    hamel_coefficients();
    equations_of_motion();
    kinematics_and_energy();
    where();
  }

 private:
  using Rows = std::vector<std::pair<std::string, std::string>>;

  std::string u(int a) { return tex.name(sys.velocities[static_cast<std::size_t>(a)].get_name()); }
  std::string q(std::size_t a) { return tex.name(sys.coordinates[a].get_name()); }
  std::string math(const GiNaC::ex& e) { return tex.expr(display(e)); }
  // One align* of `lhs &= rhs` rows, or `none` (an empty align* does not compile).
  void block(const Rows& rows, const std::string& none) {
    if (rows.empty()) {
      out << none << "\n\n";
      return;
    }
    out << "\\begin{align*}\n";
    for (std::size_t k = 0; k < rows.size(); ++k)
      out << "  " << rows[k].first << " &= " << rows[k].second << (k + 1 < rows.size() ? " \\\\\n" : "\n");
    out << "\\end{align*}\n\n";
  }
  static std::string tuple(const std::vector<std::string>& names) {
    std::string s = "(";
    for (std::size_t k = 0; k < names.size(); ++k) s += (k ? ", " : "") + names[k];
    return s + ")";
  }

  void header() {
    std::string path;
    for (char c : model.source_path) path += static_cast<unsigned char>(c) < 0x20 ? '?' : c;
    out << "% hamel derive --latex: model " << model.name << " (" << path << ", fnv1a64 " << model.source_hash
        << ")\n% A LaTeX fragment in the notation of the paper (Mueller 2023); it needs \\usepackage{amsmath}.\n";
    std::vector<std::string> independent;
    for (int a : eq.independent) independent.push_back(u(a));
    out << "\\paragraph{Model \\texttt{" << latex_text(model.name) << "}.}\nCoordinates $q = " << tuple(qs)
        << "$, quasi-velocities $u = " << tuple(us) << "$";
    if (!sys.constrained.empty()) {
      out << ", constraints $";
      for (std::size_t k = 0; k < sys.constrained.size(); ++k) out << u(sys.constrained[k]) << " = ";
      out << "0$";
    }
    out << "; independent quasi-velocities $" << tuple(independent) << "$.\n\n";
  }

  void bundle(CurvatureSign sign) {
    const Bundle& b = *model.bundle;
    const BundleGeometry& g = *d.bundle;
    std::vector<std::string> xi;
    for (const auto& s : b.group_velocity) xi.push_back(tex.name(s.get_name()));
    out << "\\paragraph{Bundle.} Group \\texttt{" << latex_text(b.group) << "}, " << (b.right ? "right" : "left")
        << " trivialization with velocity $\\xi = " << tuple(xi) << "$, "
        << (b.nonholonomic ? "nonholonomic connection (Bloch, Krishnaprasad, Marsden \\& Murray 1996)"
            : b.mechanical ? "mechanical connection (mechConn)"
                           : "kinematic connection (KinConnect)")
        << "; form " << latex_text(form_name(*d.form)) << ".\n\n";
    out << "Structure constants $c^{\\alpha}_{\\beta\\lambda}$, non-zero, $\\beta < \\lambda$ "
           "($c^{\\alpha}_{\\lambda\\beta} = -c^{\\alpha}_{\\beta\\lambda}$):\n";
    Rows rows;
    for (const StructureConstant& c : g.structure_constants)
      if (c.lower_a < c.lower_b)
        rows.emplace_back("c^{" + xi[static_cast<std::size_t>(c.upper)] + "}_{" +
                              xi[static_cast<std::size_t>(c.lower_a)] + "," + xi[static_cast<std::size_t>(c.lower_b)] +
                              "}",
                          math(c.value));
    block(rows, "none: the group is commutative.");
    out << "Connection $\\mathcal{A}^{\\alpha}_{I}$, eq.~("
        << (b.nonholonomic ? "BKMM"
            : b.mechanical ? "mechConn"
                           : "KinConnect")
        << "), non-zero entries:\n";
    rows.clear();
    if (!g.connection_derived) {
      out << "not formed symbolically for a kinematic tree: the connection kernel solves $L\\mathcal{A} = K$ "
             "numerically.\n\n";
    } else {
      for (unsigned a = 0; a < xi.size(); ++a)
        for (std::size_t I = 0; I < qs.size(); ++I) {
          const GiNaC::ex e = display(g.connection(a, static_cast<unsigned>(I)));
          if (!e.is_zero()) rows.emplace_back("\\mathcal{A}^{" + xi[a] + "}_{" + q(I) + "}", tex.expr(e));
        }
      block(rows, "none.");
      out << "Curvature $\\mathcal{B}^{\\alpha}_{IJ}$, "
          << (sign == CurvatureSign::paper ? "paper sign $\\mathcal{B} = \\gamma$"
                                           : "gauge sign $\\mathcal{B} = -\\gamma$")
          << " (remSign), non-zero, $I < J$ ($\\mathcal{B}^{\\alpha}_{JI} = -\\mathcal{B}^{\\alpha}_{IJ}$):\n";
      rows.clear();
      for (const BundleCoefficient& c : g.curvature_in(sign))
        if (c.lower_a < c.lower_b)
          rows.emplace_back("\\mathcal{B}^{" + xi[static_cast<std::size_t>(c.upper)] + "}_{" +
                                q(static_cast<std::size_t>(c.lower_a)) + "," + q(static_cast<std::size_t>(c.lower_b)) +
                                "}",
                            math(c.value));
      block(rows, "none: the connection is flat.");
    }
    out << "Reconstruction, eq.~(KinRec):\n";
    rows.clear();
    for (std::size_t a = 0; a < xi.size(); ++a) rows.emplace_back(xi[a], math(d.group_velocity[a]));
    block(rows, "none.");
  }

  void quasi_velocities() {
    out << "\\paragraph{Quasi-velocities.} $\\dot{q} = B(q)\\,u$, eq.~(u2); non-zero entries $B^{a}_{b}$:\n";
    Rows rows;
    for (unsigned r = 0; r < qs.size(); ++r)
      for (unsigned c = 0; c < us.size(); ++c) {
        const GiNaC::ex e = display(d.quasi_velocities.B(r, c));
        if (!e.is_zero()) rows.emplace_back("B^{" + qs[r] + "}_{" + us[c] + "}", tex.expr(e));
      }
    block(rows, "none.");
  }

  void hamel_coefficients() {
    out << "\\paragraph{Hamel coefficients.} Non-zero $\\gamma^{c}_{ab}$, eq.~(gamma), $a$ before $b$ in $u$ "
           "($\\gamma^{c}_{ba} = -\\gamma^{c}_{ab}$)"
        << (sys.constrained.empty() ? "" : "; $\\star$ marks $\\gamma^{a}_{IJ}$ of eq.~(gammaNH)") << ":\n";
    {
      std::set<std::array<int, 3>> present;
      for (const HamelCoefficient& h : sys.gamma) present.insert({h.upper, h.lower_a, h.lower_b});
      const auto is_independent = [&](int a) {
        return std::find(eq.independent.begin(), eq.independent.end(), a) != eq.independent.end();
      };
      Rows rows;
      for (const HamelCoefficient& h : sys.gamma) {
        if (h.lower_a > h.lower_b && present.count({h.upper, h.lower_b, h.lower_a})) continue;
        const bool star = !sys.constrained.empty() && is_independent(h.lower_a) && is_independent(h.lower_b);
        rows.emplace_back(std::string(star ? "\\star\\ " : "") + "\\gamma^{" + u(h.upper) + "}_{" + u(h.lower_a) + "," +
                              u(h.lower_b) + "}",
                          math(h.value));
      }
      block(rows, "none: the quasi-velocities are holonomic.");
    }
  }

  void equations_of_motion() {
    const std::size_t m = eq.independent.size();
    bool symmetric = true;
    for (unsigned r = 0; r < m && symmetric; ++r)
      for (unsigned c = r + 1; c < m && symmetric; ++c)
        symmetric = to_text(eq.mass_matrix(r, c)) == to_text(eq.mass_matrix(c, r));  // as printed
    out << "\\paragraph{Equations of motion.} " << latex_text(sys.form)
        << ": $M\\dot{u} = f$ in the independent quasi-velocities; non-zero entries of $M$"
        << (symmetric ? " (symmetric), $a$ before $b$" : "") << ", and $f$:\n";
    {
      Rows rows;
      for (unsigned r = 0; r < m; ++r)
        for (unsigned c = symmetric ? r : 0; c < m; ++c) {
          const GiNaC::ex e = display(eq.mass_matrix(r, c));
          if (!e.is_zero())
            rows.emplace_back("M_{" + u(eq.independent[r]) + "," + u(eq.independent[c]) + "}", tex.expr(e));
        }
      for (std::size_t r = 0; r < m; ++r) rows.emplace_back("f_{" + u(eq.independent[r]) + "}", math(eq.forcing[r]));
      block(rows, "none.");
    }
  }

  void kinematics_and_energy() {
    out << "\\paragraph{Kinematics.} Eq.~(qadot):\n";
    {
      Rows rows;
      for (std::size_t a = 0; a < qs.size(); ++a)
        rows.emplace_back(tex.name(sys.coordinates[a].get_name() + "_dot"), math(eq.kinematics[a]));
      block(rows, "none.");
    }
    out << "\\paragraph{Energy.}" << (eq.conservative ? " Conserved:" : "") << "\n";
    block({{"E", math(eq.energy_terms.at(0))}}, "");
  }

  void where() {
    // The model's own definitions come first in the program, then the intermediates the derivation named.
    const std::size_t user_definitions = model.definitions.size();
    Rows definitions, intermediates;
    for (std::size_t k = 0; k < eq.intermediates.size(); ++k) {
      const Intermediates::Definition& def = eq.intermediates.definitions()[k];
      (k < user_definitions ? definitions : intermediates)
          .emplace_back(tex.name(def.symbol.get_name()), math(def.value));
    }
    if (!definitions.empty()) {
      out << "\\paragraph{Where} (the model's definitions):\n";
      block(definitions, "");
    }
    if (!intermediates.empty()) {
      out << "\\paragraph{Where} (intermediate symbols, in evaluation order):\n";
      block(intermediates, "");
    }
  }

  std::ostream& out;
  const Model& model;
  const Derivation& d;
  const HamelSystem& sys;
  const HamelEquations& eq;
  const ExpressionDisplay& display;
  LatexPrinter tex;
  std::vector<std::string> qs, us;
};

}  // namespace

void print_derivation_latex(std::ostream& out, const Model& model, const Derivation& d, CurvatureSign sign,
                            const ExpressionDisplay& display) {
  LatexWriter(out, model, d, display).write(sign);
}

nlohmann::json derivation_json(const Model& model, const Derivation& d, const std::vector<GiNaC::ex>& accelerations,
                               const RiemannGeometry* riemann, const Intermediates& program, std::size_t derived,
                               CurvatureSign sign, const ExpressionDisplay& display, const ValueOf& value) {
  const Shown values{display, value};
  const HamelSystem& sys = d.system;
  const HamelEquations& eq = d.equations;
  const auto u_name = [&](int a) { return sys.velocities[static_cast<std::size_t>(a)].get_name(); };
  const auto q_name = [&](std::size_t a) { return sys.coordinates[a].get_name(); };
  const auto is_independent = [&](int a) {
    return std::find(eq.independent.begin(), eq.independent.end(), a) != eq.independent.end();
  };

  nlohmann::json j;
  j["model"] = model.name;
  j["source"] = {{"file", model.source_path}, {"fnv1a64", model.source_hash}};
  const unsigned n = static_cast<unsigned>(sys.coordinates.size());
  j["coordinates"] = nlohmann::json::array();
  for (std::size_t a = 0; a < n; ++a) j["coordinates"].push_back(q_name(a));
  for (std::size_t a = 0; a < sys.velocities.size(); ++a) j["quasi_velocities"].push_back(u_name(static_cast<int>(a)));
  j["constraints"] = nlohmann::json::array();
  for (int a : sys.constrained) j["constraints"].push_back(u_name(a));
  for (int a : eq.independent) j["independent"].push_back(u_name(a));
  // Position constraints g(q) = 0 (key holonomic): g and its gradient; the partition hamel chose, if it did.
  for (const PositionConstraint& c : sys.position_constraints) {
    nlohmann::json e = entry(c.g, values);
    e["name"] = c.name;
    for (std::size_t a = 0; a < n; ++a) {
      nlohmann::json g = entry(c.gradient[a], values);
      g["coordinate"] = q_name(a);
      e["gradient"].push_back(g);
    }
    j["position_constraints"].push_back(e);
  }
  if (!sys.position_constraints.empty()) {
    j["dependent_coordinates"] = nlohmann::json::array();
    for (int a : model.dependent_coordinates) j["dependent_coordinates"].push_back(q_name(static_cast<std::size_t>(a)));
  }
  if (!model.bundle)
    for (unsigned r = 0; r < n; ++r)
      for (unsigned c = 0; c < n; ++c) {
        nlohmann::json a = entry(d.quasi_velocities.A(r, c), values);
        a["row"] = u_name(static_cast<int>(r));
        a["col"] = q_name(c);
        j["A"].push_back(a);
        nlohmann::json b = entry(d.quasi_velocities.B(r, c), values);
        b["row"] = q_name(r);
        b["col"] = u_name(static_cast<int>(c));
        j["B"].push_back(b);
      }
  j["hamel"] = nlohmann::json::array();
  for (const HamelCoefficient& h : sys.gamma) {
    nlohmann::json e = entry(h.value, values);
    e["upper"] = u_name(h.upper);
    e["lower"] = {u_name(h.lower_a), u_name(h.lower_b)};
    e["lower_independent"] = is_independent(h.lower_a) && is_independent(h.lower_b);
    j["hamel"].push_back(e);
  }
  j["equations"] = sys.form;
  if (d.bundle) add_bundle_json(j, model, d, values, sign);
  const std::size_t m = eq.independent.size();
  for (std::size_t r = 0; r < m; ++r) {
    for (std::size_t c = 0; c < m; ++c) {
      nlohmann::json e = entry(eq.mass_matrix(static_cast<unsigned>(r), static_cast<unsigned>(c)), values);
      e["row"] = u_name(eq.independent[r]);
      e["col"] = u_name(eq.independent[c]);
      j["mass_matrix"].push_back(e);
    }
    nlohmann::json f = entry(eq.forcing[r], values);
    f["row"] = u_name(eq.independent[r]);
    j["forcing"].push_back(f);
  }
  for (std::size_t a = 0; a < n; ++a) {
    nlohmann::json k = entry(eq.kinematics[a], values);
    k["row"] = q_name(a) + "_dot";
    j["kinematics"].push_back(k);
  }
  j["energy"] = entry(eq.energy_terms.at(0), values);
  for (std::size_t i = 0; i < accelerations.size(); ++i) {
    nlohmann::json a = entry(accelerations[i], values);
    a["row"] = sys.velocities[static_cast<std::size_t>(eq.independent[i])].get_name() + "_rate";
    j["accelerations"].push_back(a);
  }
  // The model's own definitions come first in the program, then the intermediates the derivation named.
  const std::size_t user_definitions = model.definitions.size();
  for (std::size_t k = 0; k < derived; ++k) {
    const Intermediates::Definition& def = program.definitions()[k];
    nlohmann::json e = entry(def.value, values);
    e["name"] = def.symbol.get_name();
    j[k < user_definitions ? "definitions" : "intermediates"].push_back(e);
  }
  j["conservative"] = eq.conservative;
  if (riemann) j["riemann"] = riemann_json(*riemann, program, derived, values);

  return j;
}

// j by value: operator[] makes a missing list an empty one, as for a model without coordinates.
void print_derivation_text(std::ostream& out, nlohmann::json j, const Model& model, const Derivation& d) {
  const HamelSystem& sys = d.system;
  const HamelEquations& eq = d.equations;
  const std::size_t n = sys.coordinates.size(), m = eq.independent.size();
  auto show = [](const nlohmann::json& e) {
    std::string s = e["expr"].get<std::string>();
    if (e.contains("value")) s += "   = " + nlohmann::json(e["value"]).dump();
    return s;
  };
  out << "model " << model.name << " (" << model.source_path << "): " << n << " coordinates, " << sys.constrained.size()
      << " constraints, " << m << " independent quasi-velocities\n";
  if (j.contains("position_constraints")) {
    out << "\nposition constraints g(q) = 0, held as the quasi-velocities dg/dt = G(q) q_dot = 0, G = dg/dq "
           "(PfaffianConstr2):\n";
    for (const auto& e : j["position_constraints"])
      out << "  " << e["name"].get<std::string>() << ": g = " << show(e) << "\n";
    std::vector<std::string> dependent;
    for (const auto& e : j["dependent_coordinates"]) dependent.push_back(e.get<std::string>());
    if (!dependent.empty()) {
      std::string list;
      for (const std::string& s : dependent) list += (list.empty() ? "" : ", ") + s;
      out << "  dependent coordinates s = " << list
          << " (G_s regular at the initial configuration; the others' rates are the independent "
             "quasi-velocities, (sys1), (HE-holo))\n";
    }
  }
  if (d.bundle) {
    out << "\nbundle: G = " << j["group"]["name"].get<std::string>() << ", "
        << j["group"]["trivialization"].get<std::string>() << " trivialization, "
        << j["group"]["connection"].get<std::string>() << " connection; form " << j["form"].get<std::string>() << "\n";
    out << "\nstructure constants c^alpha_(beta,lambda), non-zero:\n";
    for (const auto& e : j["structure_constants"])
      out << "  c^" << e["alpha"].get<std::string>() << "_(" << e["beta"].get<std::string>() << ","
          << e["lambda"].get<std::string>() << ") = " << show(e) << "\n";
    out << "\nconnection A^alpha_I, "
        << (model.bundle->nonholonomic ? "nonholonomic (Bloch, Krishnaprasad, Marsden & Murray 1996)"
            : model.bundle->mechanical ? "eq. (mechConn)"
                                       : "eq. (KinConnect)")
        << ":\n";
    if (j.contains("connection_note")) out << "  " << j["connection_note"].get<std::string>() << "\n";
    for (const auto& e : j["connection"])
      if (e["expr"] != "0")
        out << "  A^" << e["alpha"].get<std::string>() << "_" << e["I"].get<std::string>() << " = " << show(e) << "\n";
    out << "\ncurvature B^alpha_IJ, " << j["curvature_sign"].get<std::string>() << ", non-zero:\n";
    if (j.contains("connection_note"))
      out << "  not derived for the recursive tree form (see the connection above)\n";
    else if (j["curvature"].empty())
      out << "  none: the connection is flat\n";
    for (const auto& e : j["curvature"])
      out << "  B^" << e["alpha"].get<std::string>() << "_(" << e["I"].get<std::string>() << ","
          << e["J"].get<std::string>() << ") = " << show(e) << "\n";
    out << "\nreconstruction xi(r, u), eq. (KinRec):\n";
    for (const auto& e : j["reconstruction"]) out << "  " << e["row"].get<std::string>() << " = " << show(e) << "\n";
    if (j.contains("nonholonomic")) {
      const auto& h = j["nonholonomic"];
      out << "\nnonholonomic momentum (Bloch, Krishnaprasad, Marsden & Murray 1996): S = D ^ V spanned by the "
             "sections Z (body frame), xi = Z Omega_S - A r_dot on D, p = Z^T dl/dxi = (Z^T L Z) Omega_S:\n";
      for (const auto& e : h["sections"])
        out << "  Z[" << e["row"].get<std::string>() << "][" << e["col"].get<std::string>() << "] = " << show(e)
            << "\n";
      for (const auto& e : h["locked_inertia"])
        out << "  I_S[" << e["row"].get<std::string>() << "][" << e["col"].get<std::string>() << "] = " << show(e)
            << "\n";
      for (const auto& e : h["kinematic_connection"])
        if (e["expr"] != "0")
          out << "  A_kin^" << e["row"].get<std::string>() << "_" << e["col"].get<std::string>() << " = " << show(e)
              << "\n";
      out << "momentum equation:\n";
      for (const auto& e : h["momentum"]) {
        out << "  " << e["name"].get<std::string>() << " = " << show(e["momentum"]) << "\n";
        out << "  " << e["name"].get<std::string>() << "' = " << show(e["rate"]) << "\n";
      }
    }
  } else {
    out << "\nB = A^-1 (q_dot = B u), non-zero entries, eq. (u2):\n";
    for (const auto& e : j["B"])
      if (e["expr"] != "0")
        out << "  B[" << e["row"].get<std::string>() << "][" << e["col"].get<std::string>() << "] = " << show(e)
            << "\n";
  }
  out << "\nnon-zero Hamel coefficients gamma^c_ab, eq. (gamma)"
      << (sys.constrained.empty() ? "" : "; * marks gamma^a_IJ of eq. (gammaNH)") << ":\n";
  if (sys.gamma.empty()) out << "  none: the quasi-velocities are holonomic\n";
  for (const auto& e : j["hamel"])
    out << "  " << (e["lower_independent"].get<bool>() && !sys.constrained.empty() ? "* " : "  ") << "gamma^"
        << e["upper"].get<std::string>() << "_(" << e["lower"][0].get<std::string>() << ","
        << e["lower"][1].get<std::string>() << ") = " << show(e) << "\n";
  out << "\n" << j["equations"].get<std::string>() << " equations  M u_I' = f:\n";
  for (const auto& e : j["mass_matrix"])
    out << "  M[" << e["row"].get<std::string>() << "][" << e["col"].get<std::string>() << "] = " << show(e) << "\n";
  for (const auto& e : j["forcing"]) out << "  f[" << e["row"].get<std::string>() << "] = " << show(e) << "\n";
  if (j.contains("definitions")) {
    out << "\ndefinitions (model key 'definitions'):\n";
    for (const auto& e : j["definitions"]) out << "  " << e["name"].get<std::string>() << " = " << show(e) << "\n";
  }
  if (j.contains("intermediates")) {
    out << "\nintermediate symbols, in evaluation order (" << j["intermediates"].size() << "):\n";
    for (const auto& e : j["intermediates"]) out << "  " << e["name"].get<std::string>() << " = " << show(e) << "\n";
  }
  out << "\nkinematics, eq. (qadot):\n";
  for (const auto& e : j["kinematics"]) out << "  " << e["row"].get<std::string>() << " = " << show(e) << "\n";
  out << "\nenergy E = " << show(j["energy"]) << (eq.conservative ? "   (conserved)" : "") << "\n";
  if (j.contains("riemann")) print_riemann(out, j["riemann"], show);
}

}  // namespace hamel
