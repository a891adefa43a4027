// SPDX-License-Identifier: MIT
// The firmware check's integration run (tests/firmware/firmware_check_test.cpp): a package's rhs integrated with the
// runtime's heap-free RK4, DOPRI5, DOP853 and Radau IIA (with the package's jacobian and with a finite-difference
// one), and the package's own rk4_step, in the package's scalar type; every final state printed bit for bit. Built for
// a Cortex-M under QEMU and for the host from this one source, so that the two runs can be compared.
// PACKAGE: the package's namespace; PACKAGE_HEADER: its header.
#include "firmware.hpp"

#include PACKAGE_HEADER

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"

namespace {

namespace pkg = PACKAGE;
using real = pkg::real;
using namespace hamel::runtime;
constexpr std::size_t n = pkg::n_state;

real inputs[pkg::n_inputs > 0 ? pkg::n_inputs : 1];
real work[BasicRadau5Workspace<real>::reals(n) + BasicDop853Workspace<real>::reals(n)];
int pivots[BasicRadau5Workspace<real>::ints(n)];
real fd_work[3 * n];

void rhs(real t, const real* x, real* f) { pkg::rhs(t, x, pkg::default_parameters, inputs, f); }
void jacobian(real t, const real* x, real* J) { pkg::jacobian(t, x, pkg::default_parameters, inputs, J); }

void initial(real* x) {
  for (std::size_t i = 0; i < n; ++i) x[i] = real(0.05) * static_cast<real>(i + 1);
}

template <class Outcome>
void report(const char* label, const Outcome& o, const real* x) {
  firmware::write_number(label, static_cast<unsigned long>(o.status));
  firmware::write_number(" steps ", static_cast<unsigned long>(o.stats.steps));
  firmware::write_number(" rhs ", static_cast<unsigned long>(o.stats.rhs_evals));
  firmware::write_bits("", x, static_cast<int>(n));
}

}  // namespace

int firmware_main() {
  const real t_end = real(1.0);
  real x[n];

  initial(x);
  report("rk4 ",
         integrate_rk4(rhs, x, n, real(0), t_end, real(0.01), real(0), NoObserver{},
                       BasicRk4Workspace<real>{work, BasicRk4Workspace<real>::reals(n)}),
         x);

  BasicDopri5Options<real> dopri5;
  dopri5.rtol = real(1e-5);
  dopri5.atol = real(1e-7);
  initial(x);
  report("dopri5 ",
         integrate_dopri5(rhs, x, n, real(0), t_end, dopri5, real(0), NoObserver{},
                          BasicDopri5Workspace<real>{work, BasicDopri5Workspace<real>::reals(n)}),
         x);

  BasicDop853Options<real> dop853;
  dop853.rtol = real(1e-5);
  dop853.atol = real(1e-7);
  initial(x);
  report("dop853 ",
         integrate_dop853(rhs, x, n, real(0), t_end, dop853, real(0), NoObserver{},
                          BasicDop853Workspace<real>{work, BasicDop853Workspace<real>::reals(n)}),
         x);

  BasicRadau5Options<real> radau5;
  radau5.rtol = real(1e-4);
  radau5.atol = real(1e-6);
  const BasicRadau5Workspace<real> radau5_work{work, BasicRadau5Workspace<real>::reals(n), pivots,
                                               BasicRadau5Workspace<real>::ints(n)};
  initial(x);
  report("radau5 ", integrate_radau5(rhs, jacobian, x, n, real(0), t_end, radau5, real(0), NoObserver{}, radau5_work),
         x);
  FiniteDifferenceJacobian finite_differences(rhs, n, fd_work);
  initial(x);
  report("radau5_fd ",
         integrate_radau5(rhs, finite_differences, x, n, real(0), t_end, radau5, real(0), NoObserver{}, radau5_work),
         x);

  initial(x);
  for (int i = 0; i < 100; ++i)
    pkg::rk4_step(real(0.01) * static_cast<real>(i), real(0.01), x, pkg::default_parameters, inputs);
  firmware::write_bits("rk4_step 0 steps 100 rhs 400", x, static_cast<int>(n));
  return 0;
}
