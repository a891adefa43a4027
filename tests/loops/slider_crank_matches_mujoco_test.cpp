// A slider-crank written in MJCF with an <equality><connect> (slider_crank.xml), imported by `hamel import` (the
// connect becomes a loop), emitted and compiled at build time, against MuJoCo and the loop's Lagrange multipliers
// solved here (nothing of hamel's derivation):
//
//   [ M(q)  Jᵀ ] [ q'' ]   [ qfrc_passive − qfrc_bias ]
//   [ J     0  ] [ lam ] = [ −J' q'                   ]
//
// M from mj_fullM, the bias (Coriolis, centrifugal, gravity) and the crank's damper from mj_forward with the equality
// constraint switched off, J = the difference of mj_jac at the two anchor points (MuJoCo's compiled anchors in the
// rod's and the slider's frames), J' q' the second derivative of the anchors' gap along q + s q' (fourth-order central
// differences of MuJoCo's kinematics); rows of J that vanish (the planar loop's y) are left out. States on the loop
// come from Newton's method on MuJoCo's gap, velocities from the null space of J.
//  (a) the emitted constraint_position is MuJoCo's gap (x and z) anywhere;
//  (b) at 20 random states on the loop, rhs gives q' and the independent joint's q'' of the multiplier system.
#include "slider_crank.hpp"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace {

struct Mujoco {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  Mujoco() {
    char err[1000] = "";
    m = mj_loadXML(HAMEL_SLIDER_CRANK_XML, nullptr, err, sizeof err);
    if (!m) throw std::runtime_error(std::string("MuJoCo: ") + err);
    m->opt.disableflags |= mjDSBL_CONSTRAINT;  // the loop is solved here, exactly
    d = mj_makeData(m);
  }
  ~Mujoco() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  int nv() const { return m->nv; }

  // The anchors in the world at q, and (optionally) the Jacobian of their gap.
  Eigen::Vector3d gap(const Eigen::VectorXd& q, Eigen::MatrixXd* J = nullptr) {
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = q[i];
    mj_kinematics(m, d);
    mj_comPos(m, d);
    const double* data = m->eq_data;
    Eigen::Vector3d p[2];
    const int body[2] = {m->eq_obj1id[0], m->eq_obj2id[0]};
    for (int k = 0; k < 2; ++k) {
      const double* a = data + 3 * k;
      const double* R = d->xmat + 9 * body[k];
      for (int r = 0; r < 3; ++r)
        p[k][r] = d->xpos[3 * body[k] + r] + R[3 * r] * a[0] + R[3 * r + 1] * a[1] + R[3 * r + 2] * a[2];
    }
    if (J) {
      J->setZero(3, nv());
      std::vector<double> jacp(3 * static_cast<std::size_t>(nv()));
      for (int k = 0; k < 2; ++k) {
        mj_jac(m, d, jacp.data(), nullptr, p[k].data(), body[k]);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < nv(); ++c) (*J)(r, c) += (k == 0 ? 1 : -1) * jacp[static_cast<std::size_t>(r * nv() + c)];
      }
    }
    return p[0] - p[1];
  }

  // q'' of the multiplier system at (q, v).
  Eigen::VectorXd accelerations(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    const int n = nv();
    Eigen::MatrixXd J;
    gap(q, &J);
    const double h = 1e-3;  // J' v = d²/ds² gap(q + s v) at s = 0
    const Eigen::Vector3d Jdv =
        (-gap(q + 2 * h * v) + 16 * gap(q + h * v) - 30 * gap(q) + 16 * gap(q - h * v) - gap(q - 2 * h * v)) /
        (12 * h * h);
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = q[i];
    for (int i = 0; i < n; ++i) d->qvel[i] = v[i];
    mj_forward(m, d);
    Eigen::MatrixXd M(n, n);
    mj_fullM(m, M.data(), d->qM);  // symmetric: row- or column-major alike
    std::vector<int> rows;
    for (int r = 0; r < 3; ++r)
      if (J.row(r).norm() > 1e-9) rows.push_back(r);
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

  // The configuration on the loop nearest q (Newton, minimum-norm steps).
  Eigen::VectorXd closed(Eigen::VectorXd q) {
    for (int it = 0; it < 50; ++it) {
      Eigen::MatrixXd J;
      const Eigen::Vector3d g = gap(q, &J);
      if (g.norm() < 1e-15) break;
      q -= J.completeOrthogonalDecomposition().solve(g);
    }
    return q;
  }
};

int independent_joint() {
  const std::string u = slider_crank::state_names[3];
  for (int a = 0; a < 3; ++a)
    if (u == std::string(slider_crank::state_names[a]) + "_dot") return a;
  ADD_FAILURE() << "the velocity " << u << " is no joint's rate";
  return 0;
}

static_assert(slider_crank::n_coordinates == 3 && slider_crank::n_independent == 1);
static_assert(slider_crank::n_out_constraint_position == 2);

TEST(SliderCrank, ConstraintPositionIsMujocosGap) {
  Mujoco mj;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), slide(-0.2, 0.2);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d q(angle(rng), angle(rng), slide(rng));
    const Eigen::Vector3d g = mj.gap(q);
    const double x[4] = {q[0], q[1], q[2], 0.0};
    double out[2];
    slider_crank::constraint_position(0.0, x, slider_crank::default_parameters, nullptr, out);
    worst = std::max({worst, std::fabs(out[0] - g[0]), std::fabs(out[1] - g[2]), std::fabs(g[1])});
  }
  std::printf("50 configurations: |g_hamel - gap_mujoco| <= %.2e (x, z; MuJoCo's y gap stays 0)\n", worst);
  EXPECT_LT(worst, 1e-14);
}

TEST(SliderCrank, RhsMatchesLagrangeMultipliersWithMujoco) {
  Mujoco mj;
  const int I = independent_joint();
  std::printf("independent joint: %s\n", slider_crank::state_names[I]);
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-10.0, 10.0);
  double worst_velocity = 0, worst_acceleration = 0, worst_closure = 0;
  for (int trial = 0; trial < 20; ++trial) {
    // A configuration on the loop near a random crank angle (the rod from the tip's circle), a velocity along it.
    const double crank = angle(rng);
    Eigen::VectorXd q0(3);
    q0 << crank, -crank, 0.0;
    const Eigen::VectorXd q = mj.closed(q0);
    Eigen::MatrixXd J;
    worst_closure = std::max(worst_closure, mj.gap(q, &J).norm());
    Eigen::FullPivLU<Eigen::MatrixXd> lu(J);
    lu.setThreshold(1e-10);
    const Eigen::MatrixXd N = lu.kernel();
    ASSERT_EQ(N.cols(), 1);
    const Eigen::VectorXd v = N.col(0) * (rate(rng) / N(0, 0));  // the crank turns at the drawn rate
    const Eigen::VectorXd a = mj.accelerations(q, v);
    const double x[4] = {q[0], q[1], q[2], v[I]};
    double f[4];
    slider_crank::rhs(0.0, x, slider_crank::default_parameters, nullptr, f);
    for (int i = 0; i < 3; ++i)
      worst_velocity = std::max(worst_velocity, std::fabs(f[i] - v[i]) / std::max(1.0, v.norm()));
    worst_acceleration = std::max(worst_acceleration, std::fabs(f[3] - a[I]) / std::max(1.0, a.norm()));
  }
  std::printf("20 states on the loop (closed to %.1e): velocities %.2e, acceleration %.2e (relative)\n", worst_closure,
              worst_velocity, worst_acceleration);
  EXPECT_LT(worst_closure, 1e-14);
  EXPECT_LT(worst_velocity, 1e-12);
  EXPECT_LT(worst_acceleration, 1e-8);  // J' v by finite differences: ~1e-10
}

}  // namespace
