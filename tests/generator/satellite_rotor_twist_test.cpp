// The paper's rotor twist is corrected here: a reaction wheel spinning about its own axis e_i through its own centre of
// mass d_i has the twist (e_i, d_i × e_i) φ̇_i relative to the base (angular, then linear at the base frame's origin);
// the paper writes (e_i φ̇_i, 0), which is the same only when d_i ∥ e_i. The satellite_se3 model is rebuilt here with
// its rotor twists generated from d_i and e_i in either convention:
//  - the generated correct-twist text reproduces models/satellite_se3.yaml's kinetic energy;
//  - with d_i ∥ e_i both conventions give the same kinetic energy (symbolically) and the same mechanical
//    connection;
//  - with the shipped d_i (not parallel) they differ: with the base at rest the correct rotors only spin,
//    T = ½ J Σ φ̇_i², while the paper's also swing their centres of mass around the base origin,
//    T = ½ J Σ φ̇_i² + ½ mr Σ |d_i × e_i|² φ̇_i².
#include "algebra/simplify.hpp"
#include "derive/bundle_connection.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace {

using GiNaC::ex;

using hamel::test::source_dir;

std::string shipped_text() {
  std::ifstream in(source_dir() + "/models/satellite_se3.yaml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* const axis_name[3] = {"x", "y", "z"};

// The rotor bodies with twists built from d_i × e_i (correct) or with zero linear part (paper).
std::string rotor_bodies(bool paper_twist) {
  std::string out;
  for (int i = 0; i < 3; ++i) {
    const std::string k = std::to_string(i + 1);
    const std::string rate = "phi" + k + "_dot";
    std::vector<GiNaC::realsymbol> d;
    for (int j = 0; j < 3; ++j) d.emplace_back("d" + k + axis_name[j]);
    // (d × e_i)_j = ε_jli d_l
    auto cross = [&](int j) -> ex {
      const int l1 = (j + 1) % 3, l2 = (j + 2) % 3;
      return (l2 == i ? ex(d[static_cast<std::size_t>(l1)]) : ex(0)) -
             (l1 == i ? ex(d[static_cast<std::size_t>(l2)]) : ex(0));
    };
    std::ostringstream body;
    body << "  - name: rotor" << k << "\n    mass: mr\n    com: [d" << k << "x, d" << k << "y, d" << k << "z]\n"
         << "    inertia: [";
    for (int r = 0; r < 3; ++r) {
      body << (r ? ", " : "") << "[";
      for (int c = 0; c < 3; ++c) body << (c ? ", " : "") << (r != c ? "0" : (r == i ? "J" : "Jt"));
      body << "]";
    }
    body << "]\n    twist: [";
    for (int j = 0; j < 3; ++j)
      body << (j ? ", " : "") << "\"w" << axis_name[j] << (j == i ? " + " + rate : "") << "\"";
    for (int j = 0; j < 3; ++j) {
      body << ", \"v" << axis_name[j];
      if (!paper_twist) body << " + (" << cross(j) << ")*" << rate;
      body << "\"";
    }
    body << "]\n";
    out += body.str();
  }
  return out;
}

hamel::Model satellite(bool paper_twist) {
  std::string text = shipped_text();
  const auto at = text.find("  - name: rotor1");
  EXPECT_NE(at, std::string::npos);
  text = text.substr(0, at) + rotor_bodies(paper_twist);
  return hamel::load_model_from_text(text, paper_twist ? "satellite_paper_twist.yaml" : "satellite_twist.yaml");
}

ex parameter(const hamel::Model& model, const std::string& name) {
  for (const auto& p : model.parameters)
    if (p.symbol.get_name() == name) return p.symbol;
  ADD_FAILURE() << "no parameter " << name;
  return 0;
}

// Expresses `e` (from `from`) in the symbols of `to`, by name.
ex rename(const ex& e, const hamel::Model& from, const hamel::Model& to) {
  GiNaC::exmap map;
  for (const auto& p : from.parameters) map[p.symbol] = parameter(to, p.symbol.get_name());
  for (std::size_t k = 0; k < from.rates.size(); ++k) map[from.rates[k]] = to.rates[k];
  for (std::size_t k = 0; k < from.coordinates.size(); ++k) map[from.coordinates[k]] = to.coordinates[k];
  for (std::size_t k = 0; k < from.bundle->group_velocity.size(); ++k)
    map[from.bundle->group_velocity[k]] = to.bundle->group_velocity[k];
  return e.subs(map);
}

hamel::Model fold(const hamel::Model& model, std::map<std::string, double> values, bool all) {
  if (all)
    for (const auto& p : model.parameters) values.emplace(p.symbol.get_name(), p.default_value);
  return hamel::fold_parameters(model, values);
}

// T with the body velocities (intermediates of the model's definitions) expanded.
GiNaC::ex kinetic(const hamel::Model& m) { return m.definitions.inline_all(m.bundle->kinetic); }

bool same_connection(const hamel::Model& a, const hamel::Model& b) {
  const GiNaC::matrix A = hamel::inlined(hamel::derive_bundle_geometry(a)).connection;
  const GiNaC::matrix B = hamel::inlined(hamel::derive_bundle_geometry(b)).connection;
  bool same = A.rows() == 6 && A.cols() == 3 && B.rows() == 6 && B.cols() == 3;
  for (unsigned i = 0; i < A.rows(); ++i)
    for (unsigned j = 0; j < A.cols(); ++j)
      same = same && hamel::is_zero_almost_surely(A(i, j) - rename(B(i, j), b, a));
  return same;
}

const std::map<std::string, double> parallel = {{"d1x", 0.3}, {"d1y", 0}, {"d1z", 0}, {"d2x", 0},  {"d2y", 0.3},
                                                {"d2z", 0},   {"d3x", 0}, {"d3y", 0}, {"d3z", 0.3}};

TEST(SatelliteRotorTwist, GeneratedCorrectTwistIsTheShippedModel) {
  const hamel::Model shipped = hamel::load_model(source_dir() + "/models/satellite_se3.yaml");
  const hamel::Model mine = satellite(false);
  EXPECT_TRUE(hamel::is_zero_almost_surely(rename(kinetic(mine), mine, shipped) - kinetic(shipped)));
  // And the paper's twist is not the shipped model.
  const hamel::Model paper = satellite(true);
  EXPECT_FALSE(hamel::is_zero_almost_surely(rename(kinetic(paper), paper, shipped) - kinetic(shipped)));
}

TEST(SatelliteRotorTwist, ConventionsAgreeWhenEachRotorCentreIsOnItsAxis) {
  const hamel::Model correct = satellite(false);
  const hamel::Model paper = satellite(true);
  // Symbolically: only the off-axis components of d_i set to zero, everything else free.
  const std::map<std::string, double> off_axis_zero = {{"d1y", 0}, {"d1z", 0}, {"d2x", 0},
                                                       {"d2z", 0}, {"d3x", 0}, {"d3y", 0}};
  const hamel::Model c = fold(correct, off_axis_zero, false);
  const hamel::Model p = fold(paper, off_axis_zero, false);
  EXPECT_TRUE(hamel::is_zero_almost_surely(rename(kinetic(p), p, c) - kinetic(c)));
  // Numerically folded (d_i = 0.3 e_i): identical kinetic energy and mechanical connection.
  const hamel::Model cf = fold(correct, parallel, true);
  const hamel::Model pf = fold(paper, parallel, true);
  EXPECT_TRUE(hamel::is_zero_almost_surely(rename(kinetic(pf), pf, cf) - kinetic(cf)));
  EXPECT_TRUE(same_connection(cf, pf));
}

TEST(SatelliteRotorTwist, ConventionsDifferWhenRotorCentresAreOffAxis) {
  const hamel::Model correct = satellite(false);
  const hamel::Model paper = satellite(true);
  ex T_correct = kinetic(correct);
  ex T_paper = rename(kinetic(paper), paper, correct);
  EXPECT_FALSE(hamel::is_zero_almost_surely(T_paper - T_correct));

  // Base at rest: ξ = 0.
  GiNaC::exmap rest;
  for (const auto& x : correct.bundle->group_velocity) rest[x] = 0;
  const ex J = parameter(correct, "J"), mr = parameter(correct, "mr");
  ex spin = 0, swing = 0;
  for (int i = 0; i < 3; ++i) {
    const ex rate = correct.rates[static_cast<std::size_t>(i)];
    spin += J * rate * rate / 2;
    // |d_i × e_i|² = |d_i|² − (d_i · e_i)²: the two components of d_i off the axis.
    ex off_axis = 0;
    for (int j = 0; j < 3; ++j)
      if (j != i) off_axis += GiNaC::pow(parameter(correct, "d" + std::to_string(i + 1) + axis_name[j]), 2);
    swing += mr * off_axis * rate * rate / 2;
  }
  EXPECT_TRUE(hamel::is_zero_almost_surely(T_correct.subs(rest) - spin)) << T_correct.subs(rest).expand();
  EXPECT_TRUE(hamel::is_zero_almost_surely(T_paper.subs(rest) - spin - swing)) << T_paper.subs(rest).expand();

  // With the shipped parameters the mechanical connections differ.
  EXPECT_FALSE(same_connection(fold(correct, {}, true), fold(paper, {}, true)));
}

}  // namespace
