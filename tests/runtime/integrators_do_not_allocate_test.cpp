// SPDX-License-Identifier: MIT
// The heap-free forms of the integrators (caller-provided work space and state buffer), the
// Munthe-Kaas integrators on Lie groups among them, allocate nothing, from the first rhs call to the
// last observer call: global operator new and delete are
// replaced by counting versions, and every run inside a counting window must leave the count at 0.
// Their results equal those of the allocating std::vector forms bit for bit, and they are accurate
// against closed-form solutions. Too small a work space, or a step or setting that makes no sense,
// is invalid_argument. The same holds with a projector onto position constraints (projection.hpp): the heap-free
// forms with a ConstraintProjector on the caller's work space allocate nothing, give the vector forms' results bit
// for bit, and keep the constraint at rounding level, where without it the drift is orders of magnitude larger.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rkmk.hpp"
#include "hamel/runtime/lie/rkmk_coupled.hpp"
#include "hamel/runtime/lie/rn.hpp"
#include "hamel/runtime/lie/se2.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "hamel/runtime/lie/so3xr3.hpp"
#include "hamel/runtime/projection.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"
#include "stiff_problems.hpp"

// --- Counting global allocation functions ---------------------------------
//
// All replaceable forms (plain, array, nothrow, aligned) count and then allocate with malloc or
// aligned_alloc; the matching deletes free. The count is global to the process, so a window must
// contain only the code under test (no gtest assertion, no printf).

namespace {

std::atomic<long> g_allocations{0};

void* counted_allocation(std::size_t size, std::size_t alignment) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  if (alignment <= alignof(std::max_align_t)) return std::malloc(size);
  // aligned_alloc wants a size that is a multiple of the alignment.
  return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}

void* counted_or_throw(std::size_t size, std::size_t alignment) {
  void* p = counted_allocation(size, alignment);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

// Not inlined into the deletes: GCC would otherwise see free() applied to what it knows as an
// operator-new pointer and warn (-Wmismatched-new-delete), although both are ours.
[[gnu::noinline]] void counted_release(void* p) noexcept { std::free(p); }

/// Counts the allocations of the whole process between its construction and count().
class AllocationCounter {
 public:
  AllocationCounter() : start_(g_allocations.load()) {}
  long count() const { return g_allocations.load() - start_; }

 private:
  long start_;
};

}  // namespace

void* operator new(std::size_t size) { return counted_or_throw(size, 0); }
void* operator new[](std::size_t size) { return counted_or_throw(size, 0); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_or_throw(size, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t size, std::align_val_t a) {
  return counted_or_throw(size, static_cast<std::size_t>(a));
}
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_allocation(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_allocation(size, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { counted_release(p); }
void operator delete[](void* p) noexcept { counted_release(p); }
void operator delete(void* p, std::size_t) noexcept { counted_release(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_release(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { counted_release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { counted_release(p); }

namespace {

using hamel::runtime::Dop853Options;
using hamel::runtime::Dop853Workspace;
using hamel::runtime::Dopri5Options;
using hamel::runtime::Dopri5Workspace;
using hamel::runtime::FiniteDifferenceJacobian;
using hamel::runtime::integrate_dop853;
using hamel::runtime::integrate_dopri5;
using hamel::runtime::integrate_radau5;
using hamel::runtime::integrate_rk4;
using hamel::runtime::IntegrationOutcome;
using hamel::runtime::IntegrationResult;
using hamel::runtime::IntegrationStats;
using hamel::runtime::NoObserver;
using hamel::runtime::Radau5Options;
using hamel::runtime::Radau5Workspace;
using hamel::runtime::Rk4Workspace;
using hamel::runtime::Status;

// Harmonic oscillator x'' = -x, x(0) = 1, x'(0) = 0: x = cos t, x' = -sin t.
constexpr std::size_t kN = 2;
void oscillator_rhs(double, const double* x, double* f) {
  f[0] = x[1];
  f[1] = -x[0];
}
void oscillator_jac(double, const double*, double* J) {
  J[0] = 0.0;
  J[1] = 1.0;
  J[2] = -1.0;
  J[3] = 0.0;
}
constexpr double kTEnd = 10.0;
constexpr double kSample = 0.1;

// Work space sized at compile time, as an emitted package would from its n_state.
double rk4_work[Rk4Workspace::doubles(kN)];
double dopri5_work[Dopri5Workspace::doubles(kN)];
double dop853_work[Dop853Workspace::doubles(kN)];
double radau5_work[Radau5Workspace::doubles(kN)];
int radau5_pivots[Radau5Workspace::ints(kN)];
double fd_work[FiniteDifferenceJacobian<void (*)(double, const double*, double*)>::doubles(kN)];

/// Observer that records (t, x...) rows into storage sized before the run, so that it allocates
/// nothing itself; rows beyond the capacity are counted, not stored.
struct Recorder {
  explicit Recorder(std::size_t capacity) : rows(capacity * (1 + kN)) {}
  void operator()(double t, const double* x) {
    if ((count + 1) * (1 + kN) > rows.size()) {
      ++overflow;
      return;
    }
    double* row = rows.data() + count * (1 + kN);
    row[0] = t;
    for (std::size_t i = 0; i < kN; ++i) row[1 + i] = x[i];
    ++count;
  }
  std::vector<double> recorded() const { return {rows.begin(), rows.begin() + static_cast<long>(count * (1 + kN))}; }
  std::vector<double> rows;
  std::size_t count = 0;
  long overflow = 0;
};

void expect_same_stats(const IntegrationStats& a, const IntegrationStats& b) {
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.rejected, b.rejected);
  EXPECT_EQ(a.rhs_evals, b.rhs_evals);
  EXPECT_EQ(a.jac_evals, b.jac_evals);
  EXPECT_EQ(a.lu_decompositions, b.lu_decompositions);
}

/// The heap-free run against the vector run: the same status, time, work, final state and observed
/// rows, compared with == (bit for bit, as none is NaN).
void expect_identical(const IntegrationOutcome& free_run, const double* x, const Recorder& free_rows,
                      const IntegrationResult& vector_run, const Recorder& vector_rows) {
  EXPECT_EQ(free_run.status, vector_run.status);
  EXPECT_EQ(free_run.t, vector_run.t);
  expect_same_stats(free_run.stats, vector_run.stats);
  ASSERT_EQ(vector_run.x.size(), kN);
  for (std::size_t i = 0; i < kN; ++i) EXPECT_EQ(x[i], vector_run.x[i]) << i;
  EXPECT_EQ(free_rows.overflow, 0);
  EXPECT_EQ(vector_rows.overflow, 0);
  EXPECT_EQ(free_rows.recorded(), vector_rows.recorded());
}

/// Largest deviation of the observed rows from cos t, -sin t; also checks the sample times.
double max_oscillator_error(const Recorder& rows) {
  double worst = 0.0;
  for (std::size_t k = 0; k < rows.count; ++k) {
    const double* row = rows.rows.data() + k * (1 + kN);
    worst = std::fmax(worst, std::fabs(row[1] - std::cos(row[0])));
    worst = std::fmax(worst, std::fabs(row[2] + std::sin(row[0])));
  }
  return worst;
}

constexpr std::size_t kRows = 200;  // kTEnd / kSample + 1 = 101 rows are expected

// The counter itself: without this the tests below could pass with a counter that never counts.
// (The pointers pass through a volatile sink so that the compiler cannot elide the new/delete pairs.)
void* volatile g_sink = nullptr;

TEST(RuntimeNoAllocation, CounterSeesAllocationsOfEveryKind) {
  AllocationCounter counter;
  {
    std::vector<double> v(3);
    g_sink = v.data();
    auto* p = new (std::nothrow) double[4];
    g_sink = p;
    delete[] p;
    struct alignas(64) Wide {
      double d[8];
    };
    auto* w = new Wide;
    g_sink = w;
    delete w;
    v.push_back(1.0);
    g_sink = v.data();
  }
  EXPECT_EQ(counter.count(), 4);
}

// The vector forms allocate (their work space and result), and the counter sees it: the windows
// below measure something.
TEST(RuntimeNoAllocation, CounterSeesTheVectorFormsAllocate) {
  const std::vector<double> x0 = {1.0, 0.0};
  AllocationCounter counter;
  const IntegrationResult r = integrate_dopri5(oscillator_rhs, x0, 0.0, 1.0, Dopri5Options{}, 0.0, NoObserver{});
  const long allocations = counter.count();
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_GE(allocations, 2);  // the copy of x0 and the work space

  AllocationCounter coupled_counter;
  const auto c = hamel::runtime::lie::integrate_rkmk4_coupled<hamel::runtime::lie::SO3>(
      hamel::runtime::lie::Trivialization::left, [](double, const double*, double* f) { f[0] = 0.0; },
      [](double, const double* x, double* xi) { xi[0] = xi[1] = xi[2] = x[0]; }, hamel::runtime::lie::SO3::identity(),
      x0, 0.0, 1.0, 0.1, 0.0, hamel::runtime::lie::NoCoupledObserver{});
  const long coupled_allocations = coupled_counter.count();
  EXPECT_EQ(c.status, Status::ok);
  EXPECT_GE(coupled_allocations, 2);  // the copy of x0 and the work space
}

TEST(RuntimeNoAllocation, Rk4) {
  Recorder free_rows(kRows), vector_rows(kRows);
  double x[kN] = {1.0, 0.0};
  AllocationCounter counter;
  const IntegrationOutcome o = integrate_rk4(oscillator_rhs, x, kN, 0.0, kTEnd, 0.01, kSample, free_rows,
                                             Rk4Workspace{rk4_work, std::size(rk4_work)});
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_EQ(o.t, kTEnd);
  EXPECT_EQ(free_rows.count, 101u);

  const IntegrationResult r = integrate_rk4(oscillator_rhs, {1.0, 0.0}, 0.0, kTEnd, 0.01, kSample, vector_rows);
  expect_identical(o, x, free_rows, r, vector_rows);
  // RK4's global error at h = 0.01 over 10 time units is about 1e-9 (h^4 t / 120 ~ 1e-9).
  const double error = max_oscillator_error(free_rows);
  std::printf("rk4: max error %.3e over %zu rows, %ld rhs\n", error, free_rows.count, o.stats.rhs_evals);
  EXPECT_LT(error, 1e-8);
}

TEST(RuntimeNoAllocation, Dopri5) {
  Dopri5Options opt;
  opt.rtol = opt.atol = 1e-10;
  Recorder free_rows(kRows), vector_rows(kRows);
  double x[kN] = {1.0, 0.0};
  AllocationCounter counter;
  const IntegrationOutcome o = integrate_dopri5(oscillator_rhs, x, kN, 0.0, kTEnd, opt, kSample, free_rows,
                                                Dopri5Workspace{dopri5_work, std::size(dopri5_work)});
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_EQ(o.t, kTEnd);
  EXPECT_EQ(free_rows.count, 101u);

  const IntegrationResult r = integrate_dopri5(oscillator_rhs, {1.0, 0.0}, 0.0, kTEnd, opt, kSample, vector_rows);
  expect_identical(o, x, free_rows, r, vector_rows);
  const double error = max_oscillator_error(free_rows);
  std::printf("dopri5: max error %.3e over %zu rows, %ld steps\n", error, free_rows.count, o.stats.steps);
  EXPECT_LT(error, 1e-8);  // tolerance 1e-10 per step, about 100 steps, plus the order-4 dense output
}

TEST(RuntimeNoAllocation, Dop853) {
  Dop853Options opt;
  opt.rtol = opt.atol = 1e-12;
  Recorder free_rows(kRows), vector_rows(kRows);
  double x[kN] = {1.0, 0.0};
  AllocationCounter counter;
  const IntegrationOutcome o = integrate_dop853(oscillator_rhs, x, kN, 0.0, kTEnd, opt, kSample, free_rows,
                                                Dop853Workspace{dop853_work, std::size(dop853_work)});
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_EQ(o.t, kTEnd);
  EXPECT_EQ(free_rows.count, 101u);

  const IntegrationResult r = integrate_dop853(oscillator_rhs, {1.0, 0.0}, 0.0, kTEnd, opt, kSample, vector_rows);
  expect_identical(o, x, free_rows, r, vector_rows);
  const double error = max_oscillator_error(free_rows);
  std::printf("dop853: max error %.3e over %zu rows, %ld steps\n", error, free_rows.count, o.stats.steps);
  EXPECT_LT(error, 1e-10);
}

TEST(RuntimeNoAllocation, Radau5OnTheOscillator) {
  Radau5Options opt;
  opt.rtol = opt.atol = 1e-10;
  Recorder free_rows(kRows), vector_rows(kRows);
  double x[kN] = {1.0, 0.0};
  const Radau5Workspace work{radau5_work, std::size(radau5_work), radau5_pivots, std::size(radau5_pivots)};
  AllocationCounter counter;
  const IntegrationOutcome o =
      integrate_radau5(oscillator_rhs, oscillator_jac, x, kN, 0.0, kTEnd, opt, kSample, free_rows, work);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_EQ(o.t, kTEnd);
  EXPECT_EQ(free_rows.count, 101u);

  const IntegrationResult r =
      integrate_radau5(oscillator_rhs, oscillator_jac, {1.0, 0.0}, 0.0, kTEnd, opt, kSample, vector_rows);
  expect_identical(o, x, free_rows, r, vector_rows);
  // Step ends within a few tolerances; samples from the cubic collocation polynomial are coarser.
  EXPECT_NEAR(x[0], std::cos(kTEnd), 1e-8);
  EXPECT_NEAR(x[1], -std::sin(kTEnd), 1e-8);
  const double error = max_oscillator_error(free_rows);
  std::printf("radau5: max error %.3e over %zu rows (end %.3e), %ld steps\n", error, free_rows.count,
              std::fmax(std::fabs(x[0] - std::cos(kTEnd)), std::fabs(x[1] + std::sin(kTEnd))), o.stats.steps);
  EXPECT_LT(error, 1e-8);
}

// Stiff Van der Pol, mu = 1000, with the analytic Jacobian and with a finite-difference Jacobian on
// the caller's work space: no allocation, the vector form's trajectory, and the half period of the
// relaxation oscillation from Dorodnitsyn's asymptotic formula (as radau5_solves_stiff_problems_test).
using hamel::runtime_test::kMu;
using hamel::runtime_test::van_der_pol_jac;
using hamel::runtime_test::van_der_pol_rhs;

/// Zero crossings of y[0] by linear interpolation between observations, into fixed storage.
struct Crossings {
  void operator()(double t, const double* y) {
    if ((x_prev > 0) != (y[0] > 0) && count < at.size()) at[count++] = t_prev + (t - t_prev) * x_prev / (x_prev - y[0]);
    t_prev = t;
    x_prev = y[0];
  }
  std::array<double, 8> at{};
  std::size_t count = 0;
  double t_prev = 0.0;
  double x_prev = 2.0;
};

template <class Jac>
void check_van_der_pol(Jac&& jac, const char* label) {
  Radau5Options opt;
  opt.rtol = opt.atol = 1e-6;
  const double t_end = 1700.0;
  double y[kN] = {2.0, 0.0};
  Crossings free_crossings, vector_crossings;
  const Radau5Workspace work{radau5_work, std::size(radau5_work), radau5_pivots, std::size(radau5_pivots)};
  AllocationCounter counter;
  const IntegrationOutcome o =
      integrate_radau5(van_der_pol_rhs, jac, y, kN, 0.0, t_end, opt, 1e-3, free_crossings, work);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0) << label;
  ASSERT_EQ(o.status, Status::ok) << label;
  EXPECT_EQ(o.t, t_end);

  const IntegrationResult r =
      integrate_radau5(van_der_pol_rhs, jac, {2.0, 0.0}, 0.0, t_end, opt, 1e-3, vector_crossings);
  EXPECT_EQ(r.status, o.status);
  expect_same_stats(o.stats, r.stats);
  EXPECT_EQ(y[0], r.x[0]);
  EXPECT_EQ(y[1], r.x[1]);
  EXPECT_EQ(free_crossings.at, vector_crossings.at);

  ASSERT_EQ(free_crossings.count, 2u) << label;
  const double alpha = 2.338107410459767;
  const double half_period =
      0.5 * ((3 - 2 * std::log(2.0)) * kMu + 3 * alpha * std::cbrt(1 / kMu) - (2.0 / 3.0) * std::log(kMu) / kMu);
  const double measured = free_crossings.at[1] - free_crossings.at[0];
  std::printf("radau5 van der pol (%s): %ld steps, half period %.5f, asymptotic %.5f\n", label, o.stats.steps, measured,
              half_period);
  EXPECT_NEAR(measured, half_period, 0.005) << label;
  EXPECT_LT(o.stats.steps, 2000) << label;  // stiff: an explicit method would need ~1e6
}

TEST(RuntimeNoAllocation, Radau5OnStiffVanDerPol) {
  check_van_der_pol(van_der_pol_jac, "analytic Jacobian");
  AllocationCounter counter;
  FiniteDifferenceJacobian fd(van_der_pol_rhs, kN, fd_work);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  check_van_der_pol(fd, "finite-difference Jacobian");
}

// Prothero-Robinson x' = lambda (x - sin t) + cos t, lambda = -1e6, x(0) = 0: x = sin t.
using hamel::runtime_test::prothero_robinson_jac;
using hamel::runtime_test::prothero_robinson_rhs;

TEST(RuntimeNoAllocation, Radau5OnStiffProtheroRobinson) {
  Radau5Options opt;
  opt.rtol = opt.atol = 1e-9;
  double x[1] = {0.0};
  double worst = 0.0;  // largest deviation from sin t at the accepted steps
  auto observe = [&](double t, const double* y) { worst = std::fmax(worst, std::fabs(y[0] - std::sin(t))); };
  const Radau5Workspace work{radau5_work, Radau5Workspace::doubles(1), radau5_pivots, Radau5Workspace::ints(1)};
  AllocationCounter counter;
  const IntegrationOutcome o =
      integrate_radau5(prothero_robinson_rhs, prothero_robinson_jac, x, 1, 0.0, 10.0, opt, 0.0, observe, work);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  std::printf("radau5 prothero-robinson: %ld steps, max error at steps %.3e\n", o.stats.steps, worst);
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(o.stats.steps, 1000);  // an explicit method needs ~1e6 steps of 2e-6
}

// --- Munthe-Kaas RK4 on Lie groups ----------------------------------------
//
// integrate_rkmk4 keeps its whole state in fixed-size values (the group element and std::array
// algebra vectors), so it has a single form, and it allocates nothing. integrate_rkmk4_coupled has
// a heap-free form for the vector part (caller's x and RkmkCoupledWorkspace) and a std::vector form
// that must agree with it bit for bit.

using hamel::runtime::lie::CoupledIntegrationOutcome;
using hamel::runtime::lie::CoupledIntegrationResult;
using hamel::runtime::lie::GroupIntegrationResult;
using hamel::runtime::lie::integrate_rkmk4;
using hamel::runtime::lie::integrate_rkmk4_coupled;
using hamel::runtime::lie::Mat3;
using hamel::runtime::lie::NoCoupledObserver;
using hamel::runtime::lie::RkmkCoupledWorkspace;
using hamel::runtime::lie::SE3;
using hamel::runtime::lie::SO3;
using hamel::runtime::lie::Trivialization;
using hamel::runtime::lie::Vec3;
using hamel::runtime::lie::Vec6;
using hamel::runtime::lie::operator*;
using hamel::runtime::lie::operator+;
using hamel::runtime::lie::operator-;

constexpr std::size_t kGroupDoubles = 12;  // an SE3 element: R and p
void flatten(const Mat3& R, double* out) {
  for (std::size_t i = 0; i < 9; ++i) out[i] = R[i];
}
void flatten(const SE3::Element& g, double* out) {
  flatten(g.R, out);
  for (std::size_t i = 0; i < 3; ++i) out[9 + i] = g.p[i];
}
template <class Element>
std::array<double, kGroupDoubles> flat(const Element& g) {
  std::array<double, kGroupDoubles> a{};
  flatten(g, a.data());
  return a;
}

/// Largest entry of |a - b| over the flattened elements.
template <class Element>
double element_distance(const Element& a, const Element& b) {
  const std::array<double, kGroupDoubles> fa = flat(a), fb = flat(b);
  double worst = 0.0;
  for (std::size_t i = 0; i < kGroupDoubles; ++i) worst = std::fmax(worst, std::fabs(fa[i] - fb[i]));
  return worst;
}

/// Records (t, x..., g...) rows of a group run into storage sized before the run (N = 0: no x).
template <std::size_t N>
struct GroupRecorder {
  static constexpr std::size_t kWidth = 1 + N + kGroupDoubles;
  explicit GroupRecorder(std::size_t capacity) : rows(capacity * kWidth) {}
  template <class Element>
  void operator()(double t, const double* x, const Element& g) {
    if ((count + 1) * kWidth > rows.size()) {
      ++overflow;
      return;
    }
    double* row = rows.data() + count * kWidth;
    row[0] = t;
    for (std::size_t i = 0; i < N; ++i) row[1 + i] = x[i];
    flatten(g, row + 1 + N);
    ++count;
  }
  template <class Element>
  void operator()(double t, const Element& g) {
    (*this)(t, nullptr, g);
  }
  std::vector<double> recorded() const { return {rows.begin(), rows.begin() + static_cast<long>(count * kWidth)}; }
  double t(std::size_t k) const { return rows[k * kWidth]; }
  const double* g(std::size_t k) const { return rows.data() + k * kWidth + 1 + N; }
  std::vector<double> rows;
  std::size_t count = 0;
  long overflow = 0;
};

// Plain RKMK4 with a velocity of fixed direction and varying size, xi(t) = (1 + sin(t)/2) xi0:
// g(t) = g0 exp(phi(t) xi0) (left) or exp(phi(t) xi0) g0 (right), phi(t) = t + (1 - cos t)/2.
double phi(double t) { return t + 0.5 * (1.0 - std::cos(t)); }

template <class Group>
void check_rkmk4(Trivialization side, const typename Group::Vector& xi0, const typename Group::Element& g0,
                 const char* label) {
  using Element = typename Group::Element;
  auto xi = [&](double t, const Element&, double* out) {
    for (std::size_t i = 0; i < Group::dim; ++i) out[i] = (1.0 + 0.5 * std::sin(t)) * xi0[i];
  };
  GroupRecorder<0> rows(kRows);
  AllocationCounter counter;
  const GroupIntegrationResult<Group> r = integrate_rkmk4<Group>(side, xi, g0, 0.0, kTEnd, 0.01, kSample, rows);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0) << label;
  ASSERT_EQ(r.status, Status::ok) << label;
  EXPECT_EQ(r.t, kTEnd) << label;
  EXPECT_EQ(rows.count, 101u) << label;
  EXPECT_EQ(rows.overflow, 0) << label;

  auto exact = [&](double t) {
    typename Group::Vector eta;
    for (std::size_t i = 0; i < Group::dim; ++i) eta[i] = phi(t) * xi0[i];
    return side == Trivialization::left ? Group::compose(g0, Group::exp(eta)) : Group::compose(Group::exp(eta), g0);
  };
  double worst = 0.0;
  for (std::size_t k = 0; k < rows.count; ++k) {
    const std::array<double, kGroupDoubles> e = flat(exact(rows.t(k)));
    for (std::size_t i = 0; i < kGroupDoubles; ++i) worst = std::fmax(worst, std::fabs(rows.g(k)[i] - e[i]));
  }
  std::printf("rkmk4 %s: max error %.3e over %zu rows, %ld evaluations\n", label, worst, rows.count, r.stats.rhs_evals);
  EXPECT_LT(worst, 1e-8) << label;
  EXPECT_LT(element_distance(r.g, exact(kTEnd)), 1e-8) << label;
}

const Mat3 kR0 = SO3::exp({0.3, -0.2, 0.5});
const SE3::Element kG0{kR0, {1.0, -2.0, 0.5}};

TEST(RuntimeNoAllocation, RkmkOnSO3AndSE3) {
  check_rkmk4<SO3>(Trivialization::left, {0.4, -1.1, 0.7}, kR0, "SO3 left");
  check_rkmk4<SO3>(Trivialization::right, {0.4, -1.1, 0.7}, kR0, "SO3 right");
  check_rkmk4<SE3>(Trivialization::left, {0.4, -1.1, 0.7, 0.3, 0.2, -0.5}, kG0, "SE3 left");
  check_rkmk4<SE3>(Trivialization::right, {0.4, -1.1, 0.7, 0.3, 0.2, -0.5}, kG0, "SE3 right");
}

// The coupled runs: a free rigid body. x = body angular velocity w (SO3) or body twist (w, v) (SE3,
// unit mass, centre of mass at the body origin) with Euler's equations I w' = (I w) x w and
// v' = v x w. Left: xi = x (body velocities). Right: xi = spatial velocities, (R w) on SO3 and
// (R w, R v - (R w) x p) on SE3, which depend on the group element. Conserved: the spatial angular
// momentum R I w and the spatial linear momentum R v; p moves uniformly, p(t) = p0 + t R0 v0.
constexpr double kInertia[3] = {1.0, 2.0, 3.0};
void euler(const double* w, double* wdot) {
  const double l0 = kInertia[0] * w[0], l1 = kInertia[1] * w[1], l2 = kInertia[2] * w[2];
  wdot[0] = (l1 * w[2] - l2 * w[1]) / kInertia[0];
  wdot[1] = (l2 * w[0] - l0 * w[2]) / kInertia[1];
  wdot[2] = (l0 * w[1] - l1 * w[0]) / kInertia[2];
}
void rigid_body(double, const double* x, double* xdot) { euler(x, xdot); }
void rigid_body_se3(double, const double* x, double* xdot) {
  euler(x, xdot);
  const Vec3 w{x[0], x[1], x[2]}, v{x[3], x[4], x[5]};
  const Vec3 vdot = hamel::runtime::lie::cross(v, w);
  for (std::size_t i = 0; i < 3; ++i) xdot[3 + i] = vdot[i];
}
void body_velocity_so3(double, const double* x, double* xi) {
  for (std::size_t i = 0; i < 3; ++i) xi[i] = x[i];
}
void spatial_velocity_so3(double, const double* x, const Mat3& R, double* xi) {
  const Vec3 ws = R * Vec3{x[0], x[1], x[2]};
  for (std::size_t i = 0; i < 3; ++i) xi[i] = ws[i];
}
void body_velocity_se3(double, const double* x, double* xi) {
  for (std::size_t i = 0; i < 6; ++i) xi[i] = x[i];
}
void spatial_velocity_se3(double, const double* x, const SE3::Element& g, double* xi) {
  const Vec3 ws = g.R * Vec3{x[0], x[1], x[2]};
  const Vec3 vs = g.R * Vec3{x[3], x[4], x[5]} - hamel::runtime::lie::cross(ws, g.p);
  for (std::size_t i = 0; i < 3; ++i) {
    xi[i] = ws[i];
    xi[3 + i] = vs[i];
  }
}

Vec3 spatial_angular_momentum(const Mat3& R, const double* w) {
  return R * Vec3{kInertia[0] * w[0], kInertia[1] * w[1], kInertia[2] * w[2]};
}
double distance(const Vec3& a, const Vec3& b) {
  return std::fmax(std::fabs(a[0] - b[0]), std::fmax(std::fabs(a[1] - b[1]), std::fabs(a[2] - b[2])));
}

// Work space sized at compile time from the number of states, as an emitted package would.
double rkmk_so3_work[RkmkCoupledWorkspace::doubles(3)];
double rkmk_se3_work[RkmkCoupledWorkspace::doubles(6)];

/// Heap-free coupled run with no allocation, then the vector form: bit-identical. x0 in, final x out.
template <class Group, std::size_t N, class F, class Xi>
CoupledIntegrationOutcome<Group> check_coupled(Trivialization side, F&& f, Xi&& xi, const typename Group::Element& g0,
                                               std::array<double, N>& x, double* work, const char* label) {
  const std::vector<double> x0(x.begin(), x.end());
  GroupRecorder<N> free_rows(kRows), vector_rows(kRows);
  AllocationCounter counter;
  const CoupledIntegrationOutcome<Group> o =
      integrate_rkmk4_coupled<Group>(side, f, xi, g0, x.data(), N, 0.0, kTEnd, 0.01, kSample, free_rows,
                                     RkmkCoupledWorkspace{work, RkmkCoupledWorkspace::doubles(N)});
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0) << label;
  EXPECT_EQ(o.status, Status::ok) << label;
  EXPECT_EQ(o.t, kTEnd) << label;
  EXPECT_EQ(free_rows.count, 101u) << label;

  const CoupledIntegrationResult<Group> r =
      integrate_rkmk4_coupled<Group>(side, f, xi, g0, x0, 0.0, kTEnd, 0.01, kSample, vector_rows);
  EXPECT_EQ(o.status, r.status) << label;
  EXPECT_EQ(o.t, r.t) << label;
  expect_same_stats(o.stats, r.stats);
  EXPECT_EQ(flat(o.g), flat(r.g)) << label;
  EXPECT_EQ(std::vector<double>(x.begin(), x.end()), r.x) << label;
  EXPECT_EQ(free_rows.overflow, 0) << label;
  EXPECT_EQ(vector_rows.overflow, 0) << label;
  EXPECT_EQ(free_rows.recorded(), vector_rows.recorded()) << label;
  return o;
}

TEST(RuntimeNoAllocation, RkmkCoupledOnSO3) {
  const std::array<double, 3> w0 = {0.3, 1.0, -0.4};  // near the unstable middle axis: a tumbling motion
  const Vec3 m0 = spatial_angular_momentum(kR0, w0.data());
  for (const Trivialization side : {Trivialization::left, Trivialization::right}) {
    const bool left = side == Trivialization::left;
    std::array<double, 3> w = w0;
    const CoupledIntegrationOutcome<SO3> o =
        left ? check_coupled<SO3>(side, rigid_body, body_velocity_so3, kR0, w, rkmk_so3_work, "SO3 left")
             : check_coupled<SO3>(side, rigid_body, spatial_velocity_so3, kR0, w, rkmk_so3_work, "SO3 right");
    const double drift = distance(spatial_angular_momentum(o.g, w.data()), m0);
    std::printf("rkmk4 coupled SO3 %s: momentum drift %.3e, %ld evaluations\n", left ? "left" : "right", drift,
                o.stats.rhs_evals);
    EXPECT_LT(drift, 1e-8);
  }
}

TEST(RuntimeNoAllocation, RkmkCoupledOnSE3) {
  const std::array<double, 6> x0 = {0.3, 1.0, -0.4, 0.5, -0.2, 0.1};
  const Vec3 m0 = spatial_angular_momentum(kG0.R, x0.data());
  const Vec3 v0 = kG0.R * Vec3{x0[3], x0[4], x0[5]};
  for (const Trivialization side : {Trivialization::left, Trivialization::right}) {
    const bool left = side == Trivialization::left;
    std::array<double, 6> x = x0;
    const CoupledIntegrationOutcome<SE3> o =
        left ? check_coupled<SE3>(side, rigid_body_se3, body_velocity_se3, kG0, x, rkmk_se3_work, "SE3 left")
             : check_coupled<SE3>(side, rigid_body_se3, spatial_velocity_se3, kG0, x, rkmk_se3_work, "SE3 right");
    const double drift = std::fmax(distance(spatial_angular_momentum(o.g.R, x.data()), m0),
                                   distance(o.g.R * Vec3{x[3], x[4], x[5]}, v0));
    const double p_error = distance(o.g.p, kG0.p + kTEnd * v0);
    std::printf("rkmk4 coupled SE3 %s: momentum drift %.3e, position error %.3e\n", left ? "left" : "right", drift,
                p_error);
    EXPECT_LT(drift, 1e-8);
    EXPECT_LT(p_error, 1e-8);
  }
}

// The group policies are fixed-size values: none of their operations allocates.
template <class Group>
double exercise(const typename Group::Vector& x) {
  const typename Group::Element g = Group::exp(x);
  const typename Group::Element h = Group::compose(g, Group::inverse(g));
  const typename Group::Vector y = Group::log(Group::compose(g, h));
  const typename Group::Matrix a = Group::dexpinv(y);
  const typename Group::Matrix b = Group::dexp(y);
  const typename Group::Matrix c = Group::Ad(g);
  const typename Group::Matrix d = Group::ad(x);
  return y[0] + a[0] + b[0] + c[0] + d[0] + (Group::is_finite(h) ? 1.0 : 0.0);
}

volatile double g_group_sink = 0.0;

TEST(RuntimeNoAllocation, GroupOperations) {
  AllocationCounter counter;
  double sum = exercise<SO3>({0.1, 0.2, 0.3});
  sum += exercise<SE3>({0.1, 0.2, 0.3, 0.4, 0.5, 0.6});
  sum += exercise<hamel::runtime::lie::SO3xR3>({0.1, 0.2, 0.3, 0.4, 0.5, 0.6});
  sum += exercise<hamel::runtime::lie::SE2>({0.1, 0.2, 0.3});
  sum += exercise<hamel::runtime::lie::Rn<2>>({0.1, 0.2});
  g_group_sink = sum;
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
}

// --- invalid_argument ------------------------------------------------------

TEST(RuntimeNoAllocation, TooSmallWorkSpaceIsAnInvalidArgument) {
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  double x[kN] = {1.0, 0.0};
  const IntegrationOutcome a = integrate_rk4(oscillator_rhs, x, kN, 0.0, 1.0, 0.1, 0.0, count,
                                             Rk4Workspace{rk4_work, Rk4Workspace::doubles(kN) - 1});
  const IntegrationOutcome b = integrate_dopri5(oscillator_rhs, x, kN, 0.0, 1.0, Dopri5Options{}, 0.0, count,
                                                Dopri5Workspace{nullptr, Dopri5Workspace::doubles(kN)});
  const IntegrationOutcome c = integrate_dop853(oscillator_rhs, x, kN, 0.0, 1.0, Dop853Options{}, 0.0, count,
                                                Dop853Workspace{dop853_work, Dop853Workspace::doubles(kN) - 1});
  const IntegrationOutcome d = integrate_radau5(
      oscillator_rhs, oscillator_jac, x, kN, 0.0, 1.0, Radau5Options{}, 0.0, count,
      Radau5Workspace{radau5_work, std::size(radau5_work), radau5_pivots, Radau5Workspace::ints(kN) - 1});
  const IntegrationOutcome e = integrate_dopri5(oscillator_rhs, nullptr, kN, 0.0, 1.0, Dopri5Options{}, 0.0, count,
                                                Dopri5Workspace{dopri5_work, std::size(dopri5_work)});
  for (const IntegrationOutcome& o : {a, b, c, d, e}) {
    EXPECT_EQ(o.status, Status::invalid_argument);
    EXPECT_EQ(o.stats.rhs_evals, 0);
    EXPECT_EQ(o.t, 0.0);
  }
  EXPECT_EQ(observed, 0);
  EXPECT_EQ(x[0], 1.0);
  EXPECT_EQ(x[1], 0.0);
}

TEST(RuntimeNoAllocation, TooSmallRkmkCoupledWorkSpaceIsAnInvalidArgument) {
  int observed = 0;
  auto count = [&](double, const double*, const Mat3&) { ++observed; };
  double w[3] = {0.3, 1.0, -0.4};
  const RkmkCoupledWorkspace small{rkmk_so3_work, RkmkCoupledWorkspace::doubles(3) - 1};
  const RkmkCoupledWorkspace null{nullptr, RkmkCoupledWorkspace::doubles(3)};
  const RkmkCoupledWorkspace fits{rkmk_so3_work, std::size(rkmk_so3_work)};
  const CoupledIntegrationOutcome<SO3> a = integrate_rkmk4_coupled<SO3>(
      Trivialization::left, rigid_body, body_velocity_so3, kR0, w, 3, 0.0, 1.0, 0.1, 0.0, count, small);
  const CoupledIntegrationOutcome<SO3> b = integrate_rkmk4_coupled<SO3>(
      Trivialization::right, rigid_body, spatial_velocity_so3, kR0, w, 3, 0.0, 1.0, 0.1, 0.0, count, null);
  const CoupledIntegrationOutcome<SO3> c = integrate_rkmk4_coupled<SO3>(
      Trivialization::left, rigid_body, body_velocity_so3, kR0, nullptr, 3, 0.0, 1.0, 0.1, 0.0, count, fits);
  for (const CoupledIntegrationOutcome<SO3>& o : {a, b, c}) {
    EXPECT_EQ(o.status, Status::invalid_argument);
    EXPECT_EQ(o.stats.rhs_evals, 0);
    EXPECT_EQ(o.t, 0.0);
    EXPECT_EQ(o.g, kR0);
  }
  EXPECT_EQ(observed, 0);
  EXPECT_EQ(w[0], 0.3);
  EXPECT_EQ(w[1], 1.0);
  EXPECT_EQ(w[2], -0.4);
}

// --- With a projector onto position constraints ------------------------------
//
// A pendulum of length 1 as a model with a holonomic constraint held in velocity form: q = (x, y) on the circle
// x^2 + y^2 = 1, the independent velocity u = omega, q' = B(q) u = (-y omega, x omega), omega' = -g x. The exact flow
// keeps x^2 + y^2, the integrators only to their error, which accumulates; the projector moves q back after every step.
constexpr std::size_t kPendulum = 3, kPendulumQ = 2, kPendulumK = 1;
constexpr double kGravity = 9.81;
void pendulum_rhs(double, const double* s, double* f) {
  f[0] = -s[1] * s[2];
  f[1] = s[0] * s[2];
  f[2] = -kGravity * s[0];
}
void pendulum_jac(double, const double* s, double* J) {
  const double j[kPendulum * kPendulum] = {0.0, -s[2], -s[1], s[2], 0.0, s[0], -kGravity, 0.0, 0.0};
  for (std::size_t i = 0; i < kPendulum * kPendulum; ++i) J[i] = j[i];
}
void circle(double, const double* s, double* g) { g[0] = s[0] * s[0] + s[1] * s[1] - 1.0; }
void circle_gradient(double, const double* s, double* G) {
  G[0] = 2.0 * s[0];
  G[1] = 2.0 * s[1];
}
using CircleProjector = hamel::runtime::ConstraintProjector<void (*)(double, const double*, double*),
                                                            void (*)(double, const double*, double*)>;
double projection_work[hamel::runtime::ProjectionWorkspace::doubles(kPendulumQ, kPendulumK)];
double pendulum_rk4_work[Rk4Workspace::doubles(kPendulum)];
double pendulum_dopri5_work[Dopri5Workspace::doubles(kPendulum)];
double pendulum_dop853_work[Dop853Workspace::doubles(kPendulum)];
double pendulum_radau5_work[Radau5Workspace::doubles(kPendulum)];
int pendulum_radau5_pivots[Radau5Workspace::ints(kPendulum)];

CircleProjector circle_projector() {
  return CircleProjector(circle, circle_gradient, kPendulumQ, kPendulumK,
                         hamel::runtime::ProjectionWorkspace{projection_work, std::size(projection_work)});
}

/// Observed rows of the pendulum in storage sized before the run, and the largest |x^2 + y^2 - 1| among them.
struct PendulumRows {
  void operator()(double t, const double* s) {
    double g = 0.0;
    circle(t, s, &g);
    drift = std::fmax(drift, std::fabs(g));
    if (count < rows.size()) rows[count] = {t, s[0], s[1], s[2]};
    ++count;
  }
  std::array<std::array<double, 4>, 2048> rows{};
  std::size_t count = 0;
  double drift = 0.0;
};

/// One integrator on the pendulum from angle 2 (x = sin 2, y = -cos 2) at rest over 20 s, sampled every 0.05 s:
/// `free_run(x, projector, rows)` is the heap-free form, `vector_run(x0, projector, rows)` the vector form,
/// `unprojected(x, rows)` the heap-free form without a projector.
template <class FreeRun, class VectorRun, class Unprojected>
void check_projected(const char* label, FreeRun free_run, VectorRun vector_run, Unprojected unprojected) {
  const double x0[kPendulum] = {std::sin(2.0), -std::cos(2.0), 0.0};
  double x[kPendulum] = {x0[0], x0[1], x0[2]};
  PendulumRows free_rows, vector_rows, plain_rows;
  CircleProjector free_projector = circle_projector();
  AllocationCounter counter;
  const IntegrationOutcome o = free_run(x, free_projector, free_rows);
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0) << label;
  ASSERT_EQ(o.status, Status::ok) << label;
  ASSERT_LE(free_rows.count, free_rows.rows.size()) << label;
  // Every accepted step and every sample is projected: the rows are t0, the samples and t_end.
  EXPECT_EQ(free_projector.stats().projections, o.stats.steps + static_cast<long>(free_rows.count) - 2) << label;

  CircleProjector vector_projector = circle_projector();
  const IntegrationResult r = vector_run(std::vector<double>(x0, x0 + kPendulum), vector_projector, vector_rows);
  EXPECT_EQ(r.status, o.status) << label;
  expect_same_stats(o.stats, r.stats);
  for (std::size_t i = 0; i < kPendulum; ++i) EXPECT_EQ(x[i], r.x[i]) << label << " " << i;
  EXPECT_EQ(free_rows.count, vector_rows.count) << label;
  EXPECT_EQ(free_rows.rows, vector_rows.rows) << label;

  double y[kPendulum] = {x0[0], x0[1], x0[2]};
  const IntegrationOutcome plain = unprojected(y, plain_rows);
  ASSERT_EQ(plain.status, Status::ok) << label;
  std::printf("%s: |x^2 + y^2 - 1| at most %.2e projected (%ld projections, %ld corrections), %.2e without\n", label,
              free_rows.drift, free_projector.stats().projections, free_projector.stats().iterations, plain_rows.drift);
  EXPECT_LT(free_rows.drift, 1e-15) << label;
  EXPECT_GT(plain_rows.drift, 100 * free_rows.drift) << label;
}

TEST(RuntimeNoAllocation, IntegratorsWithAProjector) {
  const double t_end = 20.0, sample = 0.05;
  check_projected(
      "rk4",
      [&](double* x, CircleProjector& p, PendulumRows& rows) {
        return integrate_rk4(pendulum_rhs, x, kPendulum, 0.0, t_end, 0.02, sample, rows,
                             Rk4Workspace{pendulum_rk4_work, std::size(pendulum_rk4_work)}, p);
      },
      [&](std::vector<double> x, CircleProjector& p, PendulumRows& rows) {
        return integrate_rk4(pendulum_rhs, std::move(x), 0.0, t_end, 0.02, sample, rows, p);
      },
      [&](double* x, PendulumRows& rows) {
        return integrate_rk4(pendulum_rhs, x, kPendulum, 0.0, t_end, 0.02, sample, rows,
                             Rk4Workspace{pendulum_rk4_work, std::size(pendulum_rk4_work)});
      });
  Dopri5Options o5;
  o5.rtol = o5.atol = 1e-6;
  check_projected(
      "dopri5",
      [&](double* x, CircleProjector& p, PendulumRows& rows) {
        return integrate_dopri5(pendulum_rhs, x, kPendulum, 0.0, t_end, o5, sample, rows,
                                Dopri5Workspace{pendulum_dopri5_work, std::size(pendulum_dopri5_work)}, p);
      },
      [&](std::vector<double> x, CircleProjector& p, PendulumRows& rows) {
        return integrate_dopri5(pendulum_rhs, std::move(x), 0.0, t_end, o5, sample, rows, p);
      },
      [&](double* x, PendulumRows& rows) {
        return integrate_dopri5(pendulum_rhs, x, kPendulum, 0.0, t_end, o5, sample, rows,
                                Dopri5Workspace{pendulum_dopri5_work, std::size(pendulum_dopri5_work)});
      });
  Dop853Options o8;
  o8.rtol = o8.atol = 1e-6;
  check_projected(
      "dop853",
      [&](double* x, CircleProjector& p, PendulumRows& rows) {
        return integrate_dop853(pendulum_rhs, x, kPendulum, 0.0, t_end, o8, sample, rows,
                                Dop853Workspace{pendulum_dop853_work, std::size(pendulum_dop853_work)}, p);
      },
      [&](std::vector<double> x, CircleProjector& p, PendulumRows& rows) {
        return integrate_dop853(pendulum_rhs, std::move(x), 0.0, t_end, o8, sample, rows, p);
      },
      [&](double* x, PendulumRows& rows) {
        return integrate_dop853(pendulum_rhs, x, kPendulum, 0.0, t_end, o8, sample, rows,
                                Dop853Workspace{pendulum_dop853_work, std::size(pendulum_dop853_work)});
      });
  Radau5Options o3;
  o3.rtol = o3.atol = 1e-6;
  const Radau5Workspace radau{pendulum_radau5_work, std::size(pendulum_radau5_work), pendulum_radau5_pivots,
                              std::size(pendulum_radau5_pivots)};
  check_projected(
      "radau5",
      [&](double* x, CircleProjector& p, PendulumRows& rows) {
        return integrate_radau5(pendulum_rhs, pendulum_jac, x, kPendulum, 0.0, t_end, o3, sample, rows, radau, p);
      },
      [&](std::vector<double> x, CircleProjector& p, PendulumRows& rows) {
        return integrate_radau5(pendulum_rhs, pendulum_jac, std::move(x), 0.0, t_end, o3, sample, rows, p);
      },
      [&](double* x, PendulumRows& rows) {
        return integrate_radau5(pendulum_rhs, pendulum_jac, x, kPendulum, 0.0, t_end, o3, sample, rows, radau);
      });
}

TEST(RuntimeNoAllocation, ProjectPositionsAllocatesNothing) {
  double s[kPendulum] = {1.3, -0.4, 2.0};
  AllocationCounter counter;
  const hamel::runtime::ProjectionOutcome o = hamel::runtime::project_positions(
      circle, circle_gradient, 0.0, s, kPendulumQ, kPendulumK,
      hamel::runtime::ProjectionWorkspace{projection_work, std::size(projection_work)});
  const long allocations = counter.count();
  EXPECT_EQ(allocations, 0);
  ASSERT_EQ(o.status, Status::ok);
  EXPECT_NEAR(s[0] * s[0] + s[1] * s[1], 1.0, 4e-16);
  EXPECT_EQ(s[2], 2.0);  // the velocity stays
}

}  // namespace
