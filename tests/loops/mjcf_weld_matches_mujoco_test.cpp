// A four-bar written in MJCF with an <equality><weld> (four_bar_weld.xml: the coupler welded to a hub that hinges on
// the rocker), imported by `hamel import` (the weld becomes a loop with the relative pose MuJoCo compiled), emitted and
// compiled at build time, against MuJoCo and the loop's Lagrange multipliers solved here (nothing of hamel's
// derivation). The weld's equations as MuJoCo's data define them, from its kinematics: the gap of the anchor (eq_data
// 3..5 in body1, 0..2 in body2) and vee(skew(E)), E = (R1 Q)ᵀ R2 with Q the relative pose's quaternion (6..9). J and
// J' q' by central differences of these (fourth order); rows that vanish (z, rx, ry of the planar loop) left out;
// M from mj_fullM, bias and passive (damper) forces from mj_forward with the constraint switched off.
//  (a) at 20 random states on the loop, rhs gives q' and the independent joint's q'' of the multiplier system;
//  (b) the emitted constraint_position vanishes there, and is the weld's gap (x, y) anywhere.
#include "four_bar_weld_mjcf.hpp"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace {

namespace fw = four_bar_weld_mjcf;
using Vector6 = Eigen::Matrix<double, 6, 1>;

struct Mujoco {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  Mujoco() {
    char err[1000] = "";
    m = mj_loadXML(HAMEL_FOUR_BAR_WELD_XML, nullptr, err, sizeof err);
    if (!m) throw std::runtime_error(std::string("MuJoCo: ") + err);
    m->opt.disableflags |= mjDSBL_CONSTRAINT;
    d = mj_makeData(m);
  }
  ~Mujoco() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  int nv() const { return m->nv; }

  Vector6 gap(const Eigen::VectorXd& q) {
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = q[i];
    mj_kinematics(m, d);
    const double* data = m->eq_data;
    const int b1 = m->eq_obj1id[0], b2 = m->eq_obj2id[0];
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R1(d->xmat + 9 * b1), R2(d->xmat + 9 * b2);
    const Eigen::Map<const Eigen::Vector3d> p1(d->xpos + 3 * b1), p2(d->xpos + 3 * b2), a2(data), a1(data + 3);
    const Eigen::Quaterniond Q(data[6], data[7], data[8], data[9]);
    const Eigen::Matrix3d E = (R1 * Q.normalized().toRotationMatrix()).transpose() * R2;
    Vector6 g;
    g.head<3>() = p1 + R1 * a1 - p2 - R2 * a2;
    g.tail<3>() << (E(2, 1) - E(1, 2)) / 2, (E(0, 2) - E(2, 0)) / 2, (E(1, 0) - E(0, 1)) / 2;
    return g;
  }

  Eigen::MatrixXd jacobian(const Eigen::VectorXd& q) {
    Eigen::MatrixXd J(6, nv());
    const double h = 1e-4;
    for (int c = 0; c < nv(); ++c) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(nv());
      e[c] = h;
      J.col(c) = (-gap(q + 2 * e) + 8 * gap(q + e) - 8 * gap(q - e) + gap(q - 2 * e)) / (12 * h);
    }
    return J;
  }

  Eigen::VectorXd accelerations(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    const int n = nv();
    const Eigen::MatrixXd J = jacobian(q);
    const double h = 1e-3;
    const Vector6 Jdv =
        (-gap(q + 2 * h * v) + 16 * gap(q + h * v) - 30 * gap(q) + 16 * gap(q - h * v) - gap(q - 2 * h * v)) /
        (12 * h * h);
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = q[i];
    for (int i = 0; i < n; ++i) d->qvel[i] = v[i];
    mj_forward(m, d);
    Eigen::MatrixXd M(n, n);
    mj_fullM(m, M.data(), d->qM);
    std::vector<int> rows;
    for (int r = 0; r < 6; ++r)
      if (J.row(r).norm() > 1e-8) rows.push_back(r);
    const int k = static_cast<int>(rows.size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + k, n + k);
    Eigen::VectorXd b(n + k);
    K.topLeftCorner(n, n) = M;
    for (int i = 0; i < n; ++i) b[i] = d->qfrc_passive[i] - d->qfrc_bias[i];
    for (int r = 0; r < k; ++r) {
      K.block(n + r, 0, 1, n) = J.row(rows[static_cast<std::size_t>(r)]);
      K.block(0, n + r, n, 1) = J.row(rows[static_cast<std::size_t>(r)]).transpose();
      b[n + r] = -Jdv[rows[static_cast<std::size_t>(r)]];
    }
    return K.fullPivLu().solve(b).head(n);
  }

  Eigen::VectorXd closed(Eigen::VectorXd q) {
    for (int it = 0; it < 50; ++it) {
      const Vector6 g = gap(q);
      if (g.norm() < 1e-15) break;
      q -= jacobian(q).completeOrthogonalDecomposition().solve(g);
    }
    return q;
  }
};

TEST(MjcfWeld, RhsMatchesLagrangeMultipliersWithMujoco) {
  static_assert(fw::n_coordinates == 4 && fw::n_independent == 1 && fw::n_out_constraint_position == 3);
  int I = -1;
  for (int a = 0; a < 4; ++a)
    if (std::string(fw::state_names[4]) == std::string(fw::state_names[a]) + "_dot") I = a;
  ASSERT_GE(I, 0);
  std::printf("independent joint: %s\n", fw::state_names[I]);
  Mujoco mj;
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> angle(-0.6, 0.6), rate(-10.0, 10.0);
  double worst_velocity = 0, worst_acceleration = 0, worst_g = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q0(4);
    q0 << angle(rng), 0.0, 0.0, 0.0;
    const Eigen::VectorXd q = mj.closed(q0);
    ASSERT_LT(mj.gap(q).norm(), 1e-14);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(mj.jacobian(q));
    lu.setThreshold(1e-8);
    const Eigen::MatrixXd N = lu.kernel();
    ASSERT_EQ(N.cols(), 1);
    const Eigen::VectorXd v = N.col(0) * (rate(rng) / N.col(0).norm());
    const Eigen::VectorXd a = mj.accelerations(q, v);
    const double x[5] = {q[0], q[1], q[2], q[3], v[I]};
    double f[5], g[3];
    fw::rhs(0.0, x, fw::default_parameters, nullptr, f);
    fw::constraint_position(0.0, x, fw::default_parameters, nullptr, g);
    for (int i = 0; i < 4; ++i)
      worst_velocity = std::max(worst_velocity, std::fabs(f[i] - v[i]) / std::max(1.0, v.norm()));
    worst_acceleration = std::max(worst_acceleration, std::fabs(f[4] - a[I]) / std::max(1.0, a.norm()));
    worst_g = std::max({worst_g, std::fabs(g[0]), std::fabs(g[1]), std::fabs(g[2])});
  }
  std::printf("20 states on the loop: velocities %.2e, acceleration %.2e (relative), |g_hamel| %.2e\n", worst_velocity,
              worst_acceleration, worst_g);
  EXPECT_LT(worst_velocity, 1e-9);  // the null space of a finite-difference J
  EXPECT_LT(worst_acceleration, 1e-7);
  EXPECT_LT(worst_g, 1e-14);
}

TEST(MjcfWeld, ConstraintPositionIsTheWeldsGap) {
  Mujoco mj;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector4d q(angle(rng), angle(rng), angle(rng), angle(rng));
    const Vector6 gap = mj.gap(q);
    const double x[5] = {q[0], q[1], q[2], q[3], 0.0};
    double g[3];
    fw::constraint_position(0.0, x, fw::default_parameters, nullptr, g);
    worst = std::max({worst, std::fabs(g[0] - gap[0]), std::fabs(g[1] - gap[1]), std::fabs(g[2] - gap[5])});
  }
  std::printf("50 configurations: |g_hamel - gap_mujoco| <= %.2e (x, y, rz)\n", worst);
  EXPECT_LT(worst, 1e-14);
}

}  // namespace
