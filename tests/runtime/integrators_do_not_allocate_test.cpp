// SPDX-License-Identifier: MIT
// The heap-free forms of the integrators (caller-provided work space and state buffer) allocate
// nothing, from the first rhs call to the last observer call: global operator new and delete are
// replaced by counting versions, and every run inside a counting window must leave the count at 0.
// Their results equal those of the allocating std::vector forms bit for bit, and they are accurate
// against closed-form solutions. Too small a work space, or a step or setting that makes no sense,
// is invalid_argument.
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
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

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
constexpr double kMu = 1000.0;
void van_der_pol_rhs(double, const double* y, double* f) {
  f[0] = y[1];
  f[1] = kMu * (1 - y[0] * y[0]) * y[1] - y[0];
}
void van_der_pol_jac(double, const double* y, double* J) {
  J[0] = 0.0;
  J[1] = 1.0;
  J[2] = -2 * kMu * y[0] * y[1] - 1.0;
  J[3] = kMu * (1 - y[0] * y[0]);
}

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
void prothero_robinson_rhs(double t, const double* x, double* f) { f[0] = -1e6 * (x[0] - std::sin(t)) + std::cos(t); }
void prothero_robinson_jac(double, const double*, double* J) { J[0] = -1e6; }

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

}  // namespace
