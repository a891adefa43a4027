// SPDX-License-Identifier: MIT
// project_positions (projection.hpp) against closed forms: Gauss-Newton with minimum-norm corrections moves a point
// onto a circle along its ray (the nearest point) and onto the intersection of a sphere and a plane, to rounding
// level, moving only the coordinates; it reports singular_constraint_jacobian at a point where the gradients vanish
// or become dependent, projection_failure where the constraints cannot be met, non_finite_state for NaN, and
// invalid_argument for a work space or setting that makes no sense. The integrators call a projector on every
// accepted state and sample, and the methods that reuse f at the step end (dopri5, dop853: FSAL; radau5: f at the
// step start) evaluate it again at the projected state: every projected step end is an argument of a later rhs call.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/projection.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"

namespace {

using hamel::runtime::ConstraintProjector;
using hamel::runtime::project_positions;
using hamel::runtime::ProjectionOptions;
using hamel::runtime::ProjectionOutcome;
using hamel::runtime::ProjectionWorkspace;
using hamel::runtime::Status;

void circle(double, const double* q, double* g) { g[0] = q[0] * q[0] + q[1] * q[1] - 4.0; }
void circle_gradient(double, const double* q, double* G) {
  G[0] = 2.0 * q[0];
  G[1] = 2.0 * q[1];
}

TEST(RuntimeProjection, OntoACircleAlongTheRay) {
  std::vector<double> work(ProjectionWorkspace::doubles(2, 1));
  double x[3] = {3.0, -1.2, 7.0};  // q = (3, -1.2), then a velocity the projection must not touch
  const double norm = std::hypot(3.0, -1.2);
  const ProjectionOutcome o = project_positions(circle, circle_gradient, 0.0, x, 2, 1, {work.data(), work.size()});
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_NEAR(o.residual, 3.0 * 3.0 + 1.2 * 1.2 - 4.0, 1e-15);
  // Each correction is along the gradient, the ray: the result is the nearest point 2 q / |q|.
  EXPECT_NEAR(x[0], 2.0 * 3.0 / norm, 4e-16);
  EXPECT_NEAR(x[1], 2.0 * -1.2 / norm, 4e-16);
  EXPECT_EQ(x[2], 7.0);
  EXPECT_LE(o.correction, 16 * 2.3e-16 * 2);
  EXPECT_GE(o.iterations, 3);  // quadratic convergence from 1.23 away, then one correction at rounding level
  EXPECT_LE(o.iterations, 8);
  std::printf("circle: %d corrections, last %.2e\n", o.iterations, o.correction);
}

// The unit sphere cut by the plane x + y + z = 1: a circle of radius sqrt(2/3) about (1, 1, 1)/3.
void sphere_and_plane(double, const double* q, double* g) {
  g[0] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 1.0;
  g[1] = q[0] + q[1] + q[2] - 1.0;
}
void sphere_and_plane_gradient(double, const double* q, double* G) {
  const double rows[6] = {2 * q[0], 2 * q[1], 2 * q[2], 1.0, 1.0, 1.0};
  for (int i = 0; i < 6; ++i) G[i] = rows[i];
}

TEST(RuntimeProjection, OntoTwoConstraintsAtOnce) {
  std::vector<double> work(ProjectionWorkspace::doubles(3, 2));
  double q[3] = {0.9, 0.5, -0.2};
  const ProjectionOutcome o =
      project_positions(sphere_and_plane, sphere_and_plane_gradient, 0.0, q, 3, 2, {work.data(), work.size()});
  ASSERT_EQ(o.status, Status::ok);
  double g[2];
  sphere_and_plane(0.0, q, g);
  EXPECT_LT(std::fabs(g[0]), 1e-15);
  EXPECT_LT(std::fabs(g[1]), 1e-15);
  // On the circle: distance sqrt(2/3) from its centre.
  const double c = 1.0 / 3.0;
  EXPECT_NEAR(std::hypot(std::hypot(q[0] - c, q[1] - c), q[2] - c), std::sqrt(2.0 / 3.0), 1e-15);
}

TEST(RuntimeProjection, ReportsWhatItCannotDo) {
  std::vector<double> work(ProjectionWorkspace::doubles(3, 2));
  const ProjectionWorkspace w{work.data(), work.size()};
  {  // at the centre of the circle the gradient vanishes
    double q[2] = {0.0, 0.0};
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, w).status, Status::singular_constraint_jacobian);
  }
  {  // a circle of radius^2 = -1 has no point: the iteration heads for the centre, where the gradient vanishes, or
     // runs out of corrections
    auto none = [](double, const double* q, double* g) { g[0] = q[0] * q[0] + q[1] * q[1] + 1.0; };
    double q[2] = {0.3, 0.4};
    const Status s = project_positions(none, circle_gradient, 0.0, q, 2, 1, w).status;
    EXPECT_TRUE(s == Status::projection_failure || s == Status::singular_constraint_jacobian) << describe(s);
  }
  {  // a plane and a sphere that do not meet (x + y + z = 5): no solution
    auto apart = [](double t, const double* q, double* g) {
      sphere_and_plane(t, q, g);
      g[1] -= 4.0;
    };
    double q[3] = {0.9, 0.5, -0.2};
    const Status s = project_positions(apart, sphere_and_plane_gradient, 0.0, q, 3, 2, w).status;
    EXPECT_TRUE(s == Status::projection_failure || s == Status::singular_constraint_jacobian) << describe(s);
  }
  {  // the same constraint twice: dependent everywhere
    auto twice = [](double, const double* q, double* g) { g[0] = g[1] = q[0] + q[1] - 1.0; };
    auto twice_gradient = [](double, const double*, double* G) { G[0] = G[1] = G[2] = G[3] = 1.0; };
    double q[2] = {0.3, 0.4};
    EXPECT_EQ(project_positions(twice, twice_gradient, 0.0, q, 2, 2, w).status, Status::singular_constraint_jacobian);
  }
  {
    double q[2] = {std::nan(""), 1.0};
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, w).status, Status::non_finite_state);
  }
  {
    double q[2] = {3.0, 1.0};
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, {work.data(), 3}).status,
              Status::invalid_argument);  // needs 1 * (2 + 1 + 1) = 4 doubles
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, {nullptr, 0}).status, Status::invalid_argument);
    ProjectionOptions bad;
    bad.max_iterations = 0;
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, w, bad).status, Status::invalid_argument);
    bad = ProjectionOptions{};
    bad.tolerance = -1.0;
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, w, bad).status, Status::invalid_argument);
    bad = ProjectionOptions{};
    bad.max_iterations = 1;  // one correction from 3.16 away is not at rounding level
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 2, 1, w, bad).status, Status::projection_failure);
  }
  {  // nothing to project
    double q[1] = {5.0};
    EXPECT_EQ(project_positions(circle, circle_gradient, 0.0, q, 1, 0, {nullptr, 0}).status, Status::ok);
    EXPECT_EQ(q[0], 5.0);
  }
}

// The pendulum on the circle x^2 + y^2 = 1 in the state (x, y, omega), as in integrators_do_not_allocate_test: the
// rhs logs every state it is called with, the projector every state it returns.
struct Log {
  std::vector<std::pair<double, std::vector<double>>> rhs_calls, projected;
  bool called_with(double t, const std::vector<double>& x) const {
    for (const auto& [tc, xc] : rhs_calls)
      if (tc == t && xc == x) return true;
    return false;
  }
};

template <class Run>
void check_stage_after_projection(const char* label, Run run) {
  Log log;
  auto rhs = [&](double t, const double* s, double* f) {
    log.rhs_calls.emplace_back(t, std::vector<double>(s, s + 3));
    f[0] = -s[1] * s[2];
    f[1] = s[0] * s[2];
    f[2] = -9.81 * s[0];
  };
  auto jac = [](double, const double* s, double* J) {
    const double j[9] = {0.0, -s[2], -s[1], s[2], 0.0, s[0], -9.81, 0.0, 0.0};
    for (int i = 0; i < 9; ++i) J[i] = j[i];
  };
  auto g = [](double, const double* s, double* out) { out[0] = s[0] * s[0] + s[1] * s[1] - 1.0; };
  auto G = [](double, const double* s, double* out) {
    out[0] = 2 * s[0];
    out[1] = 2 * s[1];
  };
  std::vector<double> work(ProjectionWorkspace::doubles(2, 1));
  ConstraintProjector inner(g, G, 2, 1, {work.data(), work.size()});
  auto project = [&](double t, double* x) {
    const Status s = inner(t, x);
    log.projected.emplace_back(t, std::vector<double>(x, x + 3));
    return s;
  };
  const double t_end = 3.0;
  const hamel::runtime::IntegrationResult r =
      run(rhs, jac, std::vector<double>{std::sin(2.0), -std::cos(2.0), 0.0}, t_end, project);
  ASSERT_EQ(r.status, Status::ok) << label;
  ASSERT_EQ(static_cast<long>(log.projected.size()), r.stats.steps) << label;  // no samples: the step ends
  for (const auto& [t, x] : log.projected) {
    if (t == t_end) continue;  // nothing is evaluated after the last step
    EXPECT_TRUE(log.called_with(t, x)) << label << ": no rhs call at the projected state of t = " << t;
  }
  EXPECT_EQ(r.x, log.projected.back().second) << label;
}

TEST(RuntimeProjection, TheStepAfterAProjectionStartsFromTheProjectedState) {
  check_stage_after_projection("rk4", [](auto& rhs, auto&, std::vector<double> x, double t_end, auto& project) {
    return hamel::runtime::integrate_rk4(rhs, std::move(x), 0.0, t_end, 0.05, 0.0, hamel::runtime::NoObserver{},
                                         project);
  });
  check_stage_after_projection("dopri5", [](auto& rhs, auto&, std::vector<double> x, double t_end, auto& project) {
    hamel::runtime::Dopri5Options o;
    o.rtol = o.atol = 1e-6;
    return hamel::runtime::integrate_dopri5(rhs, std::move(x), 0.0, t_end, o, 0.0, hamel::runtime::NoObserver{},
                                            project);
  });
  check_stage_after_projection("dop853", [](auto& rhs, auto&, std::vector<double> x, double t_end, auto& project) {
    hamel::runtime::Dop853Options o;
    o.rtol = o.atol = 1e-6;
    return hamel::runtime::integrate_dop853(rhs, std::move(x), 0.0, t_end, o, 0.0, hamel::runtime::NoObserver{},
                                            project);
  });
  check_stage_after_projection("radau5", [](auto& rhs, auto& jac, std::vector<double> x, double t_end, auto& project) {
    hamel::runtime::Radau5Options o;
    o.rtol = o.atol = 1e-6;
    return hamel::runtime::integrate_radau5(rhs, jac, std::move(x), 0.0, t_end, o, 0.0, hamel::runtime::NoObserver{},
                                            project);
  });
}

// A projector that fails ends the run with its status and the last accepted state.
TEST(RuntimeProjection, AFailingProjectorEndsTheRun) {
  auto rhs = [](double, const double* x, double* f) { f[0] = 1.0 + 0.0 * x[0]; };
  long calls = 0;
  auto project = [&](double t, double*) { return ++calls == 3 && t > 0 ? Status::projection_failure : Status::ok; };
  const auto r = hamel::runtime::integrate_rk4(rhs, std::vector<double>{0.0}, 0.0, 1.0, 0.1, 0.0,
                                               hamel::runtime::NoObserver{}, project);
  EXPECT_EQ(r.status, Status::projection_failure);
  EXPECT_NEAR(r.t, 0.2, 1e-15);  // steps 1 and 2 accepted, the third's projection failed
  EXPECT_NEAR(r.x[0], 0.2, 1e-15);
  calls = 0;
  hamel::runtime::Dopri5Options o;
  o.h0 = o.h_max = 0.1;
  const auto d = hamel::runtime::integrate_dopri5(rhs, std::vector<double>{0.0}, 0.0, 1.0, o, 0.0,
                                                  hamel::runtime::NoObserver{}, project);
  EXPECT_EQ(d.status, Status::projection_failure);
  EXPECT_EQ(d.stats.steps, 2);
  EXPECT_NEAR(d.t, 0.2, 1e-15);
  EXPECT_NEAR(d.x[0], 0.2, 1e-15);
}

}  // namespace
