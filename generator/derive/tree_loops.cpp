// Closed loops of a fixed-base tree as holonomic constraints; see the header.
#include "derive/tree_loops.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"
#include "derive/holonomic_constraints.hpp"
#include "derive/kinematic_tree.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "model/physical_checks.hpp"
#include "rbd/tree.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

namespace hamel {

namespace {

using GiNaC::ex;
using Vec = std::array<ex, 3>;
using Mat = std::array<Vec, 3>;

Mat product(const Mat& a, const Mat& b) {
  Mat out;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) out[r][c] = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
  return out;
}

Mat transpose(const Mat& a) {
  Mat out;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) out[r][c] = a[c][r];
  return out;
}

Vec times(const Mat& a, const Vec& v) {
  Vec out;
  for (std::size_t r = 0; r < 3; ++r) out[r] = a[r][0] * v[0] + a[r][1] * v[1] + a[r][2] * v[2];
  return out;
}

Vec sum(const Vec& a, const Vec& b, int sign = 1) {
  return {a[0] + sign * b[0], a[1] + sign * b[1], a[2] + sign * b[2]};
}

Vec substituted(const Vec& v, const GiNaC::exmap& at) { return {v[0].subs(at), v[1].subs(at), v[2].subs(at)}; }

Mat substituted(const Mat& m, const GiNaC::exmap& at) {
  Mat out;
  for (std::size_t r = 0; r < 3; ++r) out[r] = substituted(m[r], at);
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

struct Row {
  std::string name;
  ex g;
  const TreeLoop* loop;
  std::vector<ex> gradient;
};

// The rows of a maximal independent subset of `rows` (greedy: each time the row with the largest norm orthogonal to
// those already picked, ties to the earlier; stop below 1e-9 of the largest norm), ascending.
std::vector<std::size_t> independent_rows(std::vector<std::vector<double>> rows) {
  double largest = 0;
  for (const auto& r : rows) {
    double norm = 0;
    for (double v : r) norm += v * v;
    largest = std::max(largest, std::sqrt(norm));
  }
  std::vector<std::size_t> picked;
  std::vector<bool> used(rows.size(), false);
  while (largest > 0 && picked.size() < rows.size()) {
    std::size_t best = rows.size();
    double best_norm = -1;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (used[i]) continue;
      double norm = 0;
      for (double v : rows[i]) norm += v * v;
      if (norm > best_norm) best_norm = norm, best = i;
    }
    if (!(std::sqrt(best_norm) > 1e-9 * largest)) break;
    used[best] = true;
    picked.push_back(best);
    std::vector<double> unit = rows[best];
    for (double& v : unit) v /= std::sqrt(best_norm);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (used[i]) continue;
      double dot = 0;
      for (std::size_t a = 0; a < unit.size(); ++a) dot += unit[a] * rows[i][a];
      for (std::size_t a = 0; a < unit.size(); ++a) rows[i][a] -= dot * unit[a];
    }
  }
  std::sort(picked.begin(), picked.end());
  return picked;
}

}  // namespace

void close_tree_loops(Model& model, const std::vector<TreeLoop>& loops) {
  if (loops.empty() || !model.tree) return;
  const KinematicTree tree = *model.tree;
  const std::size_t n = model.n();
  const TreeDerivation d = derive_tree(model);
  const Intermediates& program = d.equations.intermediates;
  const rbd::TreeDynamics& dyn = *d.equations.tree;
  const std::vector<std::string> names = tree_body_names(tree);

  // The bodies' poses in the world, as expressions in the coordinates and parameters.
  auto rotation = [&](std::size_t i) {
    Mat R;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) R[r][c] = program.inline_all(dyn.frame.R[i][r][c]);
    return R;
  };
  auto position = [&](std::size_t i) {
    return Vec{program.inline_all(dyn.frame.p[i][0]), program.inline_all(dyn.frame.p[i][1]),
               program.inline_all(dyn.frame.p[i][2])};
  };
  auto body_index = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  GiNaC::exmap reference;  // q = 0
  for (const auto& q : model.coordinates) reference[q] = 0;

  // The closure equations of every loop, in the world frame.
  std::vector<Row> rows;
  for (const TreeLoop& loop : loops) {
    const std::size_t a = body_index(loop.body), b = body_index(loop.to);
    const Mat Ra = rotation(a), Rb = rotation(b);
    const Vec pa = position(a), pb = position(b);
    const Vec point{loop.point[0], loop.point[1], loop.point[2]};
    const Vec at_a = sum(pa, times(Ra, point));
    Vec to_point;
    if (loop.to_point) {
      to_point = {(*loop.to_point)[0], (*loop.to_point)[1], (*loop.to_point)[2]};
    } else {  // b = R_B(0)ᵀ (p_A(0) + R_A(0) a − p_B(0))
      const Vec local = times(transpose(substituted(Rb, reference)),
                              sum(substituted(at_a, reference), substituted(pb, reference), -1));
      for (std::size_t c = 0; c < 3; ++c) to_point[c] = expand_keeping_powers_of_sums(local[c]);
    }
    const Vec gap = sum(at_a, sum(pb, times(Rb, to_point)), -1);
    const char* axes[3] = {"_x", "_y", "_z"};
    for (std::size_t c = 0; c < 3; ++c) rows.push_back({loop.name + axes[c], gap[c], &loop, {}});
    if (!loop.weld) continue;
    Mat frame_a;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) frame_a[r][c] = loop.rotation[r][c];
    Mat frame_b;
    if (loop.to_rotation) {
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) frame_b[r][c] = (*loop.to_rotation)[3 * r + c];
    } else {  // R_b = R_B(0)ᵀ R_A(0) R_a
      frame_b = product(transpose(substituted(Rb, reference)), product(substituted(Ra, reference), frame_a));
      for (auto& row : frame_b)
        for (ex& e : row) e = expand_keeping_powers_of_sums(e);
    }
    const Mat E = product(transpose(product(Ra, frame_a)), product(Rb, frame_b));
    const ex vee[3] = {(E[2][1] - E[1][2]) / 2, (E[0][2] - E[2][0]) / 2, (E[1][0] - E[0][1]) / 2};
    const char* turns[3] = {"_rx", "_ry", "_rz"};
    for (std::size_t c = 0; c < 3; ++c) rows.push_back({loop.name + turns[c], vee[c], &loop, {}});
  }

  // Values: the initial configuration (the model's `initial`, other coordinates 0), parameters at their defaults.
  GiNaC::exmap initial, defaults;
  for (const Parameter& p : model.parameters) initial[p.symbol] = defaults[p.symbol] = exact_number(p.default_value);
  for (const auto& q : model.coordinates) {
    const auto it = model.initial.find(q.get_name());
    initial[q] = exact_number(it == model.initial.end() ? 0.0 : it->second);
    defaults[q] = 0;
  }

  // Rows that vanish identically go; a row that is a non-zero constant is a loop that cannot close.
  const Intermediates none;
  const std::vector<GiNaC::symbol> coordinates(model.coordinates.begin(), model.coordinates.end());
  std::vector<Row> varying;
  std::vector<std::string> dropped;
  for (Row& row : rows) {
    row.g = expand_keeping_powers_of_sums(row.g);
    bool constant = true;
    for (const auto& q : coordinates) {
      row.gradient.push_back(row.g.diff(q));
      constant =
          constant && (row.gradient.back().is_zero() || identically_zero(row.gradient.back(), none) == Identity::zero);
    }
    if (!constant) {
      varying.push_back(row);
      continue;
    }
    const double value = real_value_at(row.g, defaults);
    if (std::isnan(value) || std::fabs(value) > 1e-12)
      throw InputError(row.loop->where, "loops." + row.loop->name,
                       "the loop's equation " + row.name + " does not depend on the coordinates and is " +
                           number(value) +
                           " at the default parameters, not 0: the loop cannot close in any configuration (the two "
                           "points, or frames, are held apart along this direction); expected points that can "
                           "meet (check point, to_point and the joint offsets)");
    dropped.push_back(row.name + " (identically zero)");
  }

  // A maximal independent subset of the others: at the initial configuration, unless the rows have a larger rank at
  // one of three generic configurations (the initial one is then singular for the loops, as a four-bar stretched
  // straight is, and its rank would drop an equation that holds elsewhere): then at the first such configuration.
  std::vector<GiNaC::exmap> points{initial};
  for (std::size_t k = 0; k < 3; ++k) {
    GiNaC::exmap at = defaults;
    for (std::size_t a = 0; a < n; ++a)
      at[model.coordinates[a]] =
          exact_number(static_cast<double>((31 + 17 * a + 53 * k) % 89 + 5) / 71.0 * ((a + k) % 2 ? -1.0 : 1.0));
    points.push_back(at);
  }
  std::vector<std::size_t> kept;
  bool at_initial = true;
  for (std::size_t c = 0; c < points.size(); ++c) {
    std::vector<std::vector<double>> G;
    bool finite = true;
    for (const Row& row : varying) {
      G.emplace_back();
      for (const ex& e : row.gradient) G.back().push_back(real_value_at(e, points[c]));
      for (double v : G.back()) finite = finite && std::isfinite(v);
    }
    if (!finite) {
      if (c == 0)
        throw InputError(loops.front().where, "loops",
                         "the gradients of the loops' equations are not finite at the initial configuration; "
                         "expected a configuration where the tree's kinematics are defined");
      continue;
    }
    const std::vector<std::size_t> rows_here = independent_rows(G);
    if (rows_here.size() > kept.size()) kept = rows_here, at_initial = c == 0;
  }
  const SourceLocation where = model.locations.count("loops") ? model.locations.at("loops") : loops.front().where;
  if (kept.empty())
    throw InputError(where, "loops",
                     "the loops constrain nothing: every closure equation's gradient dg/dq vanishes at the initial "
                     "configuration; expected loops that hold the tree's bodies");
  if (kept.size() >= n)
    throw InputError(where, "loops",
                     "the loops leave no degree of freedom: " + std::to_string(kept.size()) +
                         " independent closure equations on " + std::to_string(n) +
                         " joints; expected fewer independent equations than joints");
  for (std::size_t i = 0; i < varying.size(); ++i)
    if (std::find(kept.begin(), kept.end(), i) == kept.end())
      dropped.push_back(varying[i].name + (at_initial ? " (dependent on the others at the initial configuration)"
                                                      : " (dependent on the others at a generic configuration; the "
                                                        "initial configuration is singular for the loops)"));
  if (!dropped.empty()) {
    std::string text;
    for (const std::string& s : dropped) text += (text.empty() ? "" : ", ") + s;
    std::cerr << "hamel: note: " << model.source_path << ": loops: kept " << kept.size() << " of " << rows.size()
              << " closure equations; dropped " << text << "\n";
  }

  // The general-coordinate model: L = T − V from the recursion, Q = the joint forces and Jᵀw of the wrenches.
  model.lagrangian = expand_keeping_powers_of_sums(program.inline_all(d.equations.reduced_lagrangian));
  for (std::size_t i = 0; i < n; ++i)
    model.forces[i] = model.forces[i] - tree.bodies[i].damping * model.rates[i] +
                      program.inline_all(dyn.generalized_force[i] - dyn.joint_force[i]);
  model.holonomic.clear();
  for (std::size_t i : kept) {
    model.holonomic.push_back({GiNaC::realsymbol(varying[i].name), varying[i].g, {}});
    model.locations["holonomic." + varying[i].name] = varying[i].loop->where;
    model.locations["loops." + varying[i].name] = varying[i].loop->where;
  }
  model.locations["holonomic"] = where;
  model.quasi_velocities.clear();
  model.A = GiNaC::matrix();
  model.B = GiNaC::matrix();
  model.B_given = false;
  model.constrained.clear();
  model.closed_tree = std::move(model.tree);
  model.tree.reset();
  model.wrenches.clear();
  add_holonomic_quasi_velocities(model, false);
}

}  // namespace hamel
