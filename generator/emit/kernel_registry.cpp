#include "emit/kernel_registry.hpp"

#include <stdexcept>

namespace hamel {

const std::vector<KernelSpec>& kernel_registry() {
  static const std::vector<KernelSpec> registry = {
      {"kinematics", "q_dot = B_I(q) u_I, eq. (qadot)", true},
      {"mass_matrix", "M_IJ = d2L/du^I du^J, row-major, eq. (BHconstr)", true},
      {"forcing", "f_I such that M u_I' = f, eq. (BHconstr)", true},
      {"hamel_coefficients", "non-zero gamma^c_ab, eq. (gamma); order as in hamel_upper/lower", true},
      {"rhs", "x' = (q_dot, u_I')", true},
      {"jacobian", "d(x')/dx, row-major n_state x n_state, for implicit integrators", true},
      {"energy", "E = dL/du^I u^I - L (invariant when the model is conservative)", true},
      {"linearization",
       "A = d(x')/dx (n_state x n_state) then B = d(x')/d(in) (n_state x n_in), row-major; A as jacobian for trees, "
       "otherwise forward mode through rhs",
       false},
      {"input_jacobian",
       "d(x')/d(in), row-major n_state x n_inputs: the B of the linearized dynamics beside jacobian's A (for MPC), by "
       "jacobian's route",
       false},
      {"parameter_jacobian",
       "d(x')/dp, row-major n_state x the parameters not folded (in file order, parameter_jacobian_parameters), for "
       "system identification, by jacobian's route",
       false},
      {"constraint_residual", "u^alpha = A^alpha_a(q) q_dot^a along the kinematics (zero)", true, true},
      // Models with position constraints g(q) = 0 only (holonomic constraints): what the projector needs.
      {"constraint_position", "g(q) of the position constraints g = 0, for the projector (runtime/projection.hpp)",
       true},
      {"constraint_position_jacobian",
       "G = dg/dq, row-major n_out_constraint_position x n_coordinates, for the projector (runtime/projection.hpp)",
       true},
      {"group_velocity", "xi^alpha = u^alpha - A^alpha_I r_dot^I for the reconstruction, eq. (KinRec)", true},
      {"connection", "A^alpha_I(r), row-major, eq. (KinConnect)/(mechConn)", true},
      {"locked_inertia", "L_alpha_beta(r) = d2T/dxi^alpha dxi^beta, row-major, eq. (M)", true},
      {"shape_inertia", "S - A^T L A, the shape block of M^Omega, row-major, eq. (MOmega)", true},
      {"riemann_linearization",
       "g_ab, G^a_c = Gamma^a_bc q_dot^b, K_ab = R_cbda q_dot^c q_dot^d - nabla_b Q_a at q_dot = B u, and dG/dt along "
       "x' = rhs: g D2x/dt2 + K x = Phi, D x/dt = x_dot + G x; four n x n blocks, row-major",
       false},
      {"centroidal_momentum",
       "kinematic trees: h_G = (L_G, p), the momentum about the centre of mass (6), then the centroidal momentum "
       "matrix "
       "A_G(q) with h_G = A_G u (6 x n_u, row-major), then dA_G/dt u along q_dot (6); in the base's frame (world on "
       "a fixed base)",
       false},
      // Prepared parameters (KernelSet::Prepared): by default when they save a tenth of rhs per call.
      {"rhs_prepared", "rhs reading the prepared parameters P (prepare_parameters) in place of p", true},
      {"jacobian_prepared", "jacobian reading the prepared parameters P (prepare_parameters) in place of p", true},
  };
  return registry;
}

const KernelSpec& kernel_spec(const std::string& name) {
  for (const KernelSpec& k : kernel_registry())
    if (name == k.name) return k;
  throw std::logic_error("kernel registry: no kernel named " + name);
}

bool is_kernel_name(const std::string& name) {
  for (const KernelSpec& k : kernel_registry())
    if (name == k.name) return true;
  return false;
}

std::string kernel_names() {
  std::string out;
  for (const KernelSpec& k : kernel_registry()) out += (out.empty() ? "" : ", ") + std::string(k.name);
  return out;
}

}  // namespace hamel
