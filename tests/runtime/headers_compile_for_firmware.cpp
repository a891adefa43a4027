// SPDX-License-Identifier: MIT
// The embedded core of the runtime: every header a firmware image may include (all but csv.hpp, which throws and
// streams, for hosts only), compiled together with -fno-exceptions -fno-rtti -Wdouble-promotion (tests/runtime's
// CMakeLists.txt) and its integrators instantiated in float: this file failing to compile is the test failing. csv.hpp
// throws, so with -fno-exceptions it does not compile: an embedded header that included it would fail here too.
#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/ldlt.hpp"
#include "hamel/runtime/lie/coefficients.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rkmk.hpp"
#include "hamel/runtime/lie/rkmk_coupled.hpp"
#include "hamel/runtime/lie/rn.hpp"
#include "hamel/runtime/lie/se2.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "hamel/runtime/lie/so3xr3.hpp"
#include "hamel/runtime/lu.hpp"
#include "hamel/runtime/monitor.hpp"
#include "hamel/runtime/projection.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace {
void decay(float, const float* x, float* f) { f[0] = -x[0]; }
void unit_circle(float, const float* q, float* g) { g[0] = q[0] * q[0] + q[1] * q[1] - 1.0f; }
void unit_circle_gradient(float, const float* q, float* G) {
  G[0] = 2.0f * q[0];
  G[1] = 2.0f * q[1];
}
}  // namespace

int firmware_projection_instantiates_in_float(float* q) {
  static float work[hamel::runtime::BasicProjectionWorkspace<float>::reals(2, 1)];
  using namespace hamel::runtime;
  ConstraintProjector project(unit_circle, unit_circle_gradient, 2, 1, BasicProjectionWorkspace<float>{work, 4});
  return project(0.0f, q) != Status::ok;
}

int firmware_headers_instantiate_in_float(float* x) {
  static float work[hamel::runtime::BasicRadau5Workspace<float>::reals(1) +
                    hamel::runtime::BasicDop853Workspace<float>::reals(1)];
  static int pivots[hamel::runtime::BasicRadau5Workspace<float>::ints(1)];
  static float fd_work[3];
  using namespace hamel::runtime;
  int failures = 0;
  failures +=
      integrate_rk4(decay, x, 1, 0.0f, 1.0f, 0.1f, 0.0f, NoObserver{}, BasicRk4Workspace<float>{work, 7}).status !=
      Status::ok;
  failures += integrate_dopri5(decay, x, 1, 0.0f, 1.0f, BasicDopri5Options<float>{}, 0.0f, NoObserver{},
                               BasicDopri5Workspace<float>{work, 12})
                  .status != Status::ok;
  failures += integrate_dop853(decay, x, 1, 0.0f, 1.0f, BasicDop853Options<float>{}, 0.0f, NoObserver{},
                               BasicDop853Workspace<float>{work, 26})
                  .status != Status::ok;
  FiniteDifferenceJacobian jacobian(decay, 1, fd_work);
  failures += integrate_radau5(decay, jacobian, x, 1, 0.0f, 1.0f, BasicRadau5Options<float>{}, 0.0f, NoObserver{},
                               BasicRadau5Workspace<float>{work, 29, pivots, 4})
                  .status != Status::ok;
  return failures;
}
