// The peers of hamel's kernels in tools/peer-bench (docs/benchmarks.md, "Against DART and MuJoCo"): one robot,
// read from an MJCF file by MuJoCo and rebuilt from MuJoCo's compiled model in DART, behind one interface that
// speaks hamel's coordinates. Kept apart from bench.cpp so that DART's headers are compiled once, not once per
// emitted package.
//
// hamel's state x = (q, [Γ], u): q the joint angles, Γ = Rᵀ g the gravity in the base frame (present when the
// package's state names gravity_x), u = (w, v, q̇) with (w, v) the base frame's body twist. A State adds the
// base pose, which a floating robot's dynamics does not depend on but the libraries store.
#pragma once

#include <random>
#include <string>
#include <vector>

namespace peer {

/// What the emitted package declares about its state and inputs.
struct Layout {
  int n_state = 0;
  int n_coordinates = 0;  // q and Γ
  int n_inputs = 0;
  bool gravity = false;  // x holds Γ after the joint angles
  std::vector<std::string> state_names;
  std::vector<std::string> input_names;
  int n_joints() const { return n_coordinates - (gravity ? 3 : 0); }
  int n_velocities() const { return n_state - n_coordinates; }
};

/// hamel's x and inputs, and the base pose (unit quaternion w, x, y, z; position) the libraries also store.
struct State {
  std::vector<double> x, in;
  double quat[4] = {1, 0, 0, 0};
  double pos[3] = {0, 0, 0};
};

/// A random state: base pose, joint angles in ±1.5 rad, velocities and inputs in ±1, Γ = Rᵀ g.
State random_state(const Layout& layout, const double gravity_world[3], std::mt19937_64& rng);

/// One library's model of the robot. `set` stores a state; `save`/`restore` keep states in the library's own
/// form, so that the timed loops switch between two states at the cost of a copy (the libraries cache what
/// depends only on the positions, so timing one state over and over would time a cache).
class Peer {
 public:
  virtual ~Peer() = default;
  virtual void set(const State& s) = 0;
  virtual void save(int slot) = 0;
  virtual void restore(int slot) = 0;
  /// Timed: the forward dynamics at the stored state.
  virtual void forward() = 0;
  /// After forward(): u̇ in hamel's coordinates (n_velocities entries).
  virtual void accelerations(double* udot) = 0;
  /// Timed: the mass matrix at the stored state, in the library's coordinates.
  virtual void mass_matrix() = 0;
  /// After mass_matrix(): the mass matrix in hamel's u, row-major.
  virtual void mass_matrix_hamel(double* M) = 0;
  /// Timed: what a user of the library does for ∂u̇/∂x: forward differences of its forward dynamics, one
  /// evaluation at the state and one per column of hamel's x (joint angles, gravity when the state holds it,
  /// velocities), in the library's own coordinates.
  virtual void jacobian_fd() = 0;
};

/// MuJoCo (mj_loadXML; contacts and constraints disabled). Timed forms: mj_forward, and "smooth" (the
/// smooth dynamics alone: mj_fwdPosition, mj_fwdVelocity, mj_fwdActuation, mj_fwdAcceleration).
class Mujoco : public Peer {
 public:
  Mujoco(const char* xml, const Layout& layout, bool zero_armature);
  ~Mujoco() override;
  void set(const State& s) override;
  void save(int slot) override;
  void restore(int slot) override;
  void forward() override;
  void smooth();
  void accelerations(double* udot) override;
  void smooth_accelerations(double* udot);
  void mass_matrix() override;
  void mass_matrix_hamel(double* M) override;
  void jacobian_fd() override;
  /// MuJoCo's own derivative: mjd_transitionFD (centred, ε = 1e-6) of the discrete step.
  void transition_fd();
  /// The gravity the MJCF states, in the world frame.
  const double* gravity() const;
  struct Impl;

 private:
  Impl* impl_;
};

/// DART (Skeleton::computeForwardDynamics, getMassMatrix), the skeleton built from MuJoCo's compiled model of
/// the same file: one BodyNode per hinge (massless ones where a MuJoCo body has several hinges, as hamel import
/// does), a FreeJoint at the root, full inertias, joint springs and dampers (DART treats them implicitly over a
/// time step, which is set to 1e-30 s so that its accelerations are the continuous ones), joint motors'
/// forces gear·ctrl. DART 6.12 has no armature: a model with armature is refused unless zero_armature (then
/// hamel's model must have none either).
class Dart : public Peer {
 public:
  Dart(const char* xml, const Layout& layout, bool zero_armature);
  ~Dart() override;
  void set(const State& s) override;
  void save(int slot) override;
  void restore(int slot) override;
  void forward() override;
  void accelerations(double* udot) override;
  void mass_matrix() override;
  void mass_matrix_hamel(double* M) override;
  void jacobian_fd() override;
  struct Impl;

 private:
  Impl* impl_;
};

}  // namespace peer
