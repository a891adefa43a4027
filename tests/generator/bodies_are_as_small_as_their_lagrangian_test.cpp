// A model written with `bodies:` (rigid bodies and their poses, docs/model-format.md) must derive and emit as small as
// the same model with its Lagrangian written out (issue 48): the body's angular velocity is formed from R itself,
// where RᵀR = I holds through sin² + cos² = 1, so what is exact prints exactly. Two forms of the torque-free rigid
// body in ZYX Euler angles with its body angular velocity as quasi-velocities (models/rigid_body_euler_zyx.yaml): M
// is diag(I1, I2, I3) entry by entry, and rhs takes no more operations than the hand-written Lagrangian's.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

namespace {

std::string with_bodies(std::string text) {
  const std::size_t at = text.find("lagrangian:");
  text.replace(at, std::string::npos,
               "bodies:\n"
               "  - name: body\n"
               "    mass: m\n"
               "    com: [0, 0, 0]\n"
               "    inertia: [[I1, 0, 0], [0, I2, 0], [0, 0, I3]]\n"
               "    rotation: [[z, psi], [y, theta], [x, phi]]\n"
               "    position: [0, 0, 0]\n");
  text.replace(text.find("parameters:\n"), 12, "parameters:\n  m: 1.0\n");
  return text;
}

int rhs_operations(const hamel::Model& model) {
  const hamel::Derivation d = hamel::derive(model);
  const hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs"});
  return k.graph.count(k.graph.schedule(k.get("rhs").outputs)).total();
}

TEST(BodiesAreAsSmallAsTheirLagrangian, RigidBodyInEulerAngles) {
  const std::string text = hamel::test::slurp(hamel::test::source("models/rigid_body_euler_zyx.yaml"));
  const hamel::Model lagrangian = hamel::load_model_from_text(text, "lagrangian.yaml");
  const hamel::Model bodies = hamel::load_model_from_text(with_bodies(text), "bodies.yaml");
  const hamel::Derivation d = hamel::derive(bodies);
  const GiNaC::matrix& M = d.equations.mass_matrix;
  const char* const inertia[3] = {"I1", "I2", "I3"};
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) {
      if (i != j) {
        EXPECT_TRUE(M(i, j).is_zero()) << "M[" << i << "][" << j << "] = " << M(i, j);
        continue;
      }
      std::ostringstream printed;
      printed << M(i, i);
      EXPECT_EQ(printed.str(), inertia[i]);
    }
  const int by_hand = rhs_operations(lagrangian), from_bodies = rhs_operations(bodies);
  std::printf("rhs operations: Lagrangian written out %d, bodies %d\n", by_hand, from_bodies);
  EXPECT_LE(from_bodies, 1.2 * by_hand);
}

}  // namespace
