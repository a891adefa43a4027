// Imported robots against peers that share nothing with hamel's derivation:
//  - MuJoCo's sample humanoid (21 hinges on a free torso, joints with several hinges per body, fixed head
//    and hands merged, inertias MuJoCo infers from capsules, armature, damping, stiffness, motors with
//    gears), imported from MJCF with contacts and limits left out, emitted and compiled: its rhs against
//    mj_forward with contacts and limits disabled, at 20 random states, base orientations and controls, with
//    gravity (the state then holds Γ = Rᵀ g, gravity in the torso's frame, set from MuJoCo's quaternion) and
//    without (imported with --ignore gravity too);
//  - the 7-joint URDF arm (make_arm7.py: rotated joint origins, inclined axes, damping, a continuous joint,
//    a fixed flange merged into link 7), imported from URDF with --floating: against its MJCF twin in MuJoCo
//    (written independently from the same numbers) and against the Eigen Newton-Euler of tests/tree.
// State mapping (as tools/scaling/harness.cpp): hamel x = (q, [Γ,] w, v, q_dot) with (w, v) the base frame's body
// twist; MuJoCo's free joint qpos = (p, quat), qvel = (R v, w). Back: w_dot = qacc_ang, v_dot = Rᵀ qacc_lin −
// w × v. Tolerance: |a_hamel − a_ref|_inf ≤ 1e-10 max(1, |a_ref|_inf).
#include "tree_from_model.hpp"
#include "tree_reference.hpp"

#include "arm7.hpp"
#include "arm7_fixed.hpp"
#include "humanoid.hpp"
#include "humanoid_gravity.hpp"
#include "import/tree_import.hpp"
#include "model/expression_parser.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

constexpr double kTolerance = 1e-10;
constexpr int kStates = 20;

using Kernel = void (*)(double, const double*, const double*, const double*, double*);

struct Package {
  Kernel rhs, energy;
  bool floating;
  bool gravity_state;  // x holds Γ = Rᵀ g after q
  int n;               // joints (the coordinates but Γ)
  const char* const* state_names;
  const char* const* input_names;
  int n_inputs;
  std::string input_prefix;  // input = prefix + actuator name
};

struct Mujoco {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  Mujoco(const char* path, bool keep_gravity) {  // NOLINT
    char err[1000] = "";
    m = mj_loadXML(path, nullptr, err, sizeof err);
    if (!m) throw std::runtime_error(std::string("MuJoCo: ") + err);
    // The import left contacts and limits out (and gravity on a floating base): MuJoCo without them.
    m->opt.disableflags |= mjDSBL_CONSTRAINT;
    if (!keep_gravity) m->opt.gravity[0] = m->opt.gravity[1] = m->opt.gravity[2] = 0;
    m->opt.enableflags |= mjENBL_ENERGY;
    d = mj_makeData(m);
  }
  ~Mujoco() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
};

void quat_to_R(const double* q, double R[3][3]) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0][0] = 1 - 2 * (y * y + z * z), R[0][1] = 2 * (x * y - w * z), R[0][2] = 2 * (x * z + w * y);
  R[1][0] = 2 * (x * y + w * z), R[1][1] = 1 - 2 * (x * x + z * z), R[1][2] = 2 * (y * z - w * x);
  R[2][0] = 2 * (x * z - w * y), R[2][1] = 2 * (y * z + w * x), R[2][2] = 1 - 2 * (x * x + y * y);
}

struct Sample {
  std::vector<double> x, in, quat, p;
};

Sample random_sample(std::mt19937_64& rng, const Package& pkg, const double* gravity = nullptr) {
  std::uniform_real_distribution<double> u(-1, 1);
  Sample s;
  const int base = pkg.floating ? 6 : 0;
  for (int i = 0; i < 2 * pkg.n + base; ++i) s.x.push_back(i < pkg.n ? 1.5 * u(rng) : 2 * u(rng));
  for (int k = 0; k < pkg.n_inputs; ++k) s.in.push_back(u(rng));
  double n = 0;
  for (int k = 0; k < 4; ++k) {
    s.quat.push_back(u(rng));
    n += s.quat.back() * s.quat.back();
  }
  for (double& c : s.quat) c /= std::sqrt(n);
  for (int k = 0; k < 3; ++k) s.p.push_back(u(rng));
  if (pkg.gravity_state) {  // Γ = Rᵀ g: gravity in the torso's frame at this orientation, after q
    double R[3][3];
    quat_to_R(s.quat.data(), R);
    for (int i = 3; i-- > 0;)
      s.x.insert(s.x.begin() + pkg.n, R[0][i] * gravity[0] + R[1][i] * gravity[1] + R[2][i] * gravity[2]);
  }
  return s;
}

// (w_dot, v_dot, q_ddot) (floating) or q_ddot (fixed base) from MuJoCo for the hamel state of a sample;
// `energy` gets MuJoCo's potential plus kinetic energy.
std::vector<double> mujoco_accelerations(Mujoco& mj, const Package& pkg, const Sample& s, double& energy) {
  const int n = pkg.n, base = pkg.floating ? 6 : 0;
  double R[3][3];
  quat_to_R(s.quat.data(), R);
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const int G = pkg.gravity_state ? 3 : 0;
  const double* w = pkg.floating ? s.x.data() + n + G : zero;
  const double* v = pkg.floating ? s.x.data() + n + G + 3 : zero;
  mj_resetData(mj.m, mj.d);
  if (pkg.floating) {
    for (int k = 0; k < 3; ++k) mj.d->qpos[k] = s.p[static_cast<std::size_t>(k)];
    for (int k = 0; k < 4; ++k) mj.d->qpos[3 + k] = s.quat[static_cast<std::size_t>(k)];
    for (int i = 0; i < 3; ++i) {
      mj.d->qvel[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
      mj.d->qvel[3 + i] = w[i];
    }
  }
  std::vector<int> dof(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const int j = mj_name2id(mj.m, mjOBJ_JOINT, pkg.state_names[i]);
    if (j < 0) throw std::runtime_error(std::string("no MuJoCo joint ") + pkg.state_names[i]);
    mj.d->qpos[mj.m->jnt_qposadr[j]] = s.x[static_cast<std::size_t>(i)];
    dof[static_cast<std::size_t>(i)] = mj.m->jnt_dofadr[j];
    mj.d->qvel[dof[static_cast<std::size_t>(i)]] = s.x[static_cast<std::size_t>(n + G + base + i)];
  }
  for (int k = 0; k < pkg.n_inputs; ++k) {
    const std::string name = std::string(pkg.input_names[k]).substr(pkg.input_prefix.size());
    const int a = mj_name2id(mj.m, mjOBJ_ACTUATOR, name.c_str());
    if (a < 0) throw std::runtime_error("no MuJoCo actuator " + name);
    mj.d->ctrl[a] = s.in[static_cast<std::size_t>(k)];
  }
  mj_forward(mj.m, mj.d);
  mj_energyVel(mj.m, mj.d);
  energy = mj.d->energy[0] + mj.d->energy[1];
  const double* qacc = mj.d->qacc;
  const double wxv[3] = {w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0]};
  std::vector<double> a;
  for (int i = 0; i < 3 && pkg.floating; ++i) a.push_back(qacc[3 + i]);
  for (int i = 0; i < 3 && pkg.floating; ++i)
    a.push_back(R[0][i] * qacc[0] + R[1][i] * qacc[1] + R[2][i] * qacc[2] - wxv[i]);
  for (int i = 0; i < n; ++i) a.push_back(qacc[dof[static_cast<std::size_t>(i)]]);
  return a;
}

// (ẇ, v̇, q̈), or q̈ on a fixed base; Γ̇ is checked to be Γ × ω.
std::vector<double> hamel_accelerations(const Package& pkg, const Sample& s) {
  std::vector<double> out(s.x.size());
  pkg.rhs(0, s.x.data(), nullptr, s.in.data(), out.data());
  const int G = pkg.gravity_state ? 3 : 0;
  for (int i = 0; i < G; ++i) {
    const double* g = s.x.data() + pkg.n;
    const double* w = g + 3;
    const double rate = g[(i + 1) % 3] * w[(i + 2) % 3] - g[(i + 2) % 3] * w[(i + 1) % 3];
    EXPECT_NEAR(out[static_cast<std::size_t>(pkg.n + i)], rate, 1e-12 * (1 + std::abs(rate)));
  }
  return std::vector<double>(out.begin() + pkg.n + G, out.end());
}

double relative_error(const std::vector<double>& a, const std::vector<double>& ref) {
  double err = 0, scale = 1;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    err = std::max(err, std::abs(a[k] - ref[k]));
    scale = std::max(scale, std::abs(ref[k]));
  }
  return err / scale;
}

// Accelerations at kStates random states; the energy kernel against MuJoCo's energy up to a constant (MuJoCo
// counts the weight of bodies welded to the world too), compared as differences to the first state.
// A floating base under gravity has no energy invariant in hamel's state (the height is not in it): then only the
// accelerations are compared.
void expect_matches_mujoco(const Package& pkg, const char* xml, unsigned seed) {
  Mujoco mj(xml, !pkg.floating || pkg.gravity_state);
  ASSERT_EQ(mj.m->nv, pkg.n + (pkg.floating ? 6 : 0));
  std::mt19937_64 rng(seed);
  double worst = 0, offset = 0;
  for (int k = 0; k < kStates; ++k) {
    const Sample s = random_sample(rng, pkg, mj.m->opt.gravity);
    double mj_energy = 0, energy = 0;
    const std::vector<double> ref = mujoco_accelerations(mj, pkg, s, mj_energy);
    const double e = relative_error(hamel_accelerations(pkg, s), ref);
    worst = std::max(worst, e);
    EXPECT_LE(e, kTolerance) << "state " << k;
    if (pkg.floating && pkg.gravity_state) continue;
    pkg.energy(0, s.x.data(), nullptr, s.in.data(), &energy);
    if (k == 0) offset = energy - mj_energy;
    EXPECT_NEAR(energy - mj_energy, offset, 1e-10 * std::max(1.0, std::abs(mj_energy))) << "state " << k;
  }
  std::printf("%s: worst relative error against mj_forward %.2e over %d states\n", xml, worst, kStates);
}

const Package humanoid_pkg{
    humanoid::rhs,         humanoid::energy,   true, false, humanoid::n_coordinates, humanoid::state_names,
    humanoid::input_names, humanoid::n_inputs, "u_"};
const Package humanoid_gravity_pkg{humanoid_gravity::rhs,
                                   humanoid_gravity::energy,
                                   true,
                                   true,
                                   humanoid_gravity::n_coordinates - 3,  // the joints; then Γ
                                   humanoid_gravity::state_names,
                                   humanoid_gravity::input_names,
                                   humanoid_gravity::n_inputs,
                                   "u_"};
const Package arm7_pkg{arm7::rhs,         arm7::energy,      true,           false, arm7::n_coordinates,
                       arm7::state_names, arm7::input_names, arm7::n_inputs, ""};
const Package arm7_fixed_pkg{
    arm7_fixed::rhs,         arm7_fixed::energy,   false, false, arm7_fixed::n_coordinates, arm7_fixed::state_names,
    arm7_fixed::input_names, arm7_fixed::n_inputs, "u_"};

TEST(ImportedHumanoid, RhsMatchesMujocoForward) {
  static_assert(humanoid::n_coordinates == 21 && humanoid::n_inputs == 21, "the humanoid has 21 hinges and motors");
  expect_matches_mujoco(humanoid_pkg, HAMEL_HUMANOID_XML, 15);
}

TEST(ImportedHumanoid, RhsUnderGravityMatchesMujocoForwardAtEveryOrientation) {
  static_assert(humanoid_gravity::n_state == 2 * 21 + 3 + 6, "gravity in the torso's frame is part of the state");
  expect_matches_mujoco(humanoid_gravity_pkg, HAMEL_HUMANOID_XML, 16);
}

// The centroidal momentum kernel against MuJoCo's own momentum of the torso's subtree (the whole humanoid):
// mj_subtreeVel's angular momentum about the subtree's centre of mass and its centre-of-mass velocity times its mass,
// in the world frame, turned into the torso's frame (the kernel's). Then A_G u = h_G, and dA_G/dt u against central
// differences of the kernel's A_G along q_dot with u held.
TEST(ImportedHumanoid, CentroidalMomentumMatchesMujocosSubtreeMomentum) {
  const Package& pkg = humanoid_pkg;
  Mujoco mj(HAMEL_HUMANOID_XML, false);
  const int torso = mj_name2id(mj.m, mjOBJ_BODY, "torso");
  ASSERT_GE(torso, 1);
  const int n = pkg.n, nu = n + 6;
  ASSERT_EQ(humanoid::n_out_centroidal_momentum, 6 + 6 * nu + 6);
  const std::size_t rate_at = static_cast<std::size_t>(6 + 6 * nu);
  std::mt19937_64 rng(17);
  double worst = 0, worst_matrix = 0, worst_rate = 0;
  for (int k = 0; k < kStates; ++k) {
    const Sample s = random_sample(rng, pkg);
    double energy = 0;
    mujoco_accelerations(mj, pkg, s, energy);  // MuJoCo at this state (mj_forward)
    mj_subtreeVel(mj.m, mj.d);
    double R[3][3];
    quat_to_R(s.quat.data(), R);
    const double mass = mj.m->body_subtreemass[torso];
    std::vector<double> ref(6, 0.0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        ref[static_cast<std::size_t>(i)] += R[j][i] * mj.d->subtree_angmom[3 * torso + j];
        ref[static_cast<std::size_t>(3 + i)] += R[j][i] * mass * mj.d->subtree_linvel[3 * torso + j];
      }
    std::vector<double> out(static_cast<std::size_t>(humanoid::n_out_centroidal_momentum));
    humanoid::centroidal_momentum(0, s.x.data(), nullptr, s.in.data(), out.data());
    const std::vector<double> h(out.begin(), out.begin() + 6);
    worst = std::max(worst, relative_error(h, ref));
    // h_G = A_G u, u = (ξ, ṙ) = x after the n joint angles.
    const double* u = s.x.data() + n;
    std::vector<double> Au(6, 0.0);
    for (std::size_t r = 0; r < 6; ++r)
      for (int I = 0; I < nu; ++I)
        Au[r] += out[6 + r * static_cast<std::size_t>(nu) + static_cast<std::size_t>(I)] * u[I];
    worst_matrix = std::max(worst_matrix, relative_error(Au, ref));
    // dA_G/dt u: A_G at q ± ε q_dot (q_dot = ṙ), u held.
    const double eps = 1e-6;
    std::vector<double> fd(6, 0.0);
    for (const double sign : {1.0, -1.0}) {
      std::vector<double> x = s.x, o(out.size());
      for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] += sign * eps * u[6 + i];
      humanoid::centroidal_momentum(0, x.data(), nullptr, s.in.data(), o.data());
      for (std::size_t r = 0; r < 6; ++r)
        for (int I = 0; I < nu; ++I)
          fd[r] += sign * o[6 + r * static_cast<std::size_t>(nu) + static_cast<std::size_t>(I)] * u[I] / (2 * eps);
    }
    worst_rate = std::max(worst_rate, relative_error(std::vector<double>(out.begin() + static_cast<long>(rate_at),
                                                                         out.begin() + static_cast<long>(rate_at) + 6),
                                                     fd));
  }
  std::printf(
      "humanoid centroidal momentum against mj_subtreeVel: h_G %.2e, A_G u %.2e; dA_G/dt u against central "
      "differences %.2e (%d states)\n",
      worst, worst_matrix, worst_rate, kStates);
  EXPECT_LE(worst, 1e-12);
  EXPECT_LE(worst_matrix, 1e-12);
  EXPECT_LE(worst_rate, 1e-7);
}

TEST(ImportedUrdfArm, RhsMatchesItsMjcfTwinInMujoco) {
  static_assert(arm7::n_coordinates == 7, "seven revolute joints; the fixed flange is merged");
  expect_matches_mujoco(arm7_pkg, HAMEL_ARM7_XML, 7);
}

TEST(ImportedFixedArm, RhsAndEnergyUnderGravityMatchMujoco) {
  static_assert(arm7_fixed::n_state == 14, "a fixed base has no group velocity");
  expect_matches_mujoco(arm7_fixed_pkg, HAMEL_ARM7_FIXED_XML, 11);
}

TEST(ImportedUrdfArm, RhsMatchesNewtonEuler) {
  const hamel::Model model = hamel::load_model(std::string(HAMEL_IMPORT_DIR) + "/arm7.yaml");
  const tree_ref::Tree tree = tree_ref::tree_of(model);
  ASSERT_EQ(tree.n(), 7);
  std::vector<double> damping;
  for (const hamel::TreeBody& b : model.bundle->tree->bodies)
    damping.push_back(GiNaC::ex_to<GiNaC::numeric>(b.damping.evalf()).to_double());
  std::mt19937_64 rng(3);
  for (int k = 0; k < kStates; ++k) {
    const Sample s = random_sample(rng, arm7_pkg);
    tree_ref::VX q(7), xi(6), qd(7), Q(7);
    for (int i = 0; i < 7; ++i) {
      q[i] = s.x[static_cast<std::size_t>(i)];
      qd[i] = s.x[static_cast<std::size_t>(13 + i)];
      Q[i] = s.in[static_cast<std::size_t>(i)] - damping[static_cast<std::size_t>(i)] * qd[i];
    }
    for (int a = 0; a < 6; ++a) xi[a] = s.x[static_cast<std::size_t>(7 + a)];
    const tree_ref::VX acc = tree_ref::accelerations(tree, q, xi, qd, Q);
    std::vector<double> ref;
    for (int i = 0; i < acc.size(); ++i) ref.push_back(static_cast<double>(acc[i]));
    EXPECT_LE(relative_error(hamel_accelerations(arm7_pkg, s), ref), kTolerance) << "state " << k;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// What the tree format cannot hold: an error naming the file, the line and the element, or, under --ignore,
// a warning and a model without it.

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path;
}

std::string import_error(const std::string& path, const hamel::ImportOptions& options, bool urdf) {
  try {
    const hamel::Warn quiet = [](const std::string&) {};
    if (urdf)
      hamel::import_urdf(path, options, quiet);
    else
      hamel::import_mjcf(path, options, quiet);
  } catch (const hamel::InputError& e) {
    return e.what();
  }
  return "";
}

const char* ball_mjcf = R"(<mujoco model="m">
  <worldbody>
    <body name="a">
      <freejoint/>
      <geom type="sphere" size=".1" contype="0" conaffinity="0"/>
      <body name="b" pos="0 0 .3">
        <joint name="shoulder" type="ball"/>
        <geom type="sphere" size=".1" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
</mujoco>
)";

TEST(ImportErrors, BallJointNamesFileLineAndJoint) {
  const std::string path = write_temp("ball.xml", ball_mjcf);
  const std::string e = import_error(path, {}, false);
  EXPECT_NE(e.find(path + ":7:"), std::string::npos) << e;
  EXPECT_NE(e.find("'shoulder'"), std::string::npos) << e;
  EXPECT_NE(e.find("ball joints"), std::string::npos) << e;
}

TEST(ImportErrors, ContactsAndTendonsNeedIgnore) {
  std::string text = ball_mjcf;
  text.replace(text.find("type=\"ball\""), 11, "type=\"hinge\"");
  text.replace(text.find("contype=\"0\" conaffinity=\"0\""), 27, "contype=\"1\"");
  text.replace(text.find("</worldbody>"), 12,
               "</worldbody><tendon><fixed name=\"tie\"><joint joint=\"shoulder\" coef=\"1\"/></fixed></tendon>");
  const std::string path = write_temp("contacts.xml", text);
  const std::string e = import_error(path, {}, false);
  EXPECT_NE(e.find("--ignore tendons"), std::string::npos) << e;
  EXPECT_NE(e.find(path + ":"), std::string::npos) << e;
  hamel::ImportOptions o;
  o.ignore = {"tendons"};
  EXPECT_NE(import_error(path, o, false).find("--ignore contacts"), std::string::npos);
  o.ignore = {"tendons", "contacts", "gravity"};
  std::vector<std::string> warnings;
  const hamel::ImportedTree t = hamel::import_mjcf(path, o, [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_EQ(t.bodies.size(), 1u);
  EXPECT_EQ(warnings.size(), 3u);
  EXPECT_NE(hamel::tree_model_yaml(t).find("left out: tendons, contacts, gravity"), std::string::npos);
}

TEST(ImportErrors, UrdfPlanarJointIsRefused) {
  const std::string path = write_temp("planar.urdf", R"(<robot name="r">
  <link name="a"/>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="slider" type="planar"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
</robot>
)");
  const std::string e = import_error(path, {}, true);
  EXPECT_NE(e.find(path + ":4:"), std::string::npos) << e;
  EXPECT_NE(e.find("'joint 'slider''"), std::string::npos) << e;
}

// Names a robot file leaves empty or gives in characters C++ does not take: an unnamed body with several unnamed
// joints (as in MuJoCo's composite/particle.xml) asks for the body name "_", which looped forever; "_x", "a::b"
// and a repeated keyword had no valid form either. Every body, joint and input gets a valid, distinct name, and
// the written model loads.
TEST(ImportNames, UnnamedAndUnusableNamesBecomeDistinctIdentifiers) {
  const std::string path = write_temp("names.xml", R"(<mujoco model="names">
  <option gravity="0 0 0"/>
  <worldbody>
    <body pos="0 0 0"><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/><joint type="slide" axis="0 0 1"/>
      <geom type="sphere" size=".1" contype="0" conaffinity="0"/></body>
    <body pos="1 0 0"><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/><joint type="slide" axis="0 0 1"/>
      <geom type="sphere" size=".1" contype="0" conaffinity="0"/></body>
    <body name="_x" pos="2 0 0"><joint name="a::b" type="hinge" axis="0 0 1"/>
      <geom type="sphere" size=".1" contype="0" conaffinity="0"/>
      <body name="int" pos="0 0 1"><joint name="int" type="hinge" axis="1 0 0"/>
        <geom type="sphere" size=".1" contype="0" conaffinity="0"/>
        <body name="int_" pos="0 0 1"><joint name="x_dot" type="hinge" axis="0 1 0"/>
          <geom type="sphere" size=".1" contype="0" conaffinity="0"/></body></body></body>
  </worldbody>
  <actuator><motor joint="int"/><motor name="__" joint="x_dot"/></actuator>
</mujoco>
)");
  const hamel::ImportedTree t = hamel::import_mjcf(path, {}, [](const std::string&) {});
  ASSERT_EQ(t.bodies.size(), 9u);
  std::set<std::string> bodies, symbols;
  for (const hamel::ImportedBody& b : t.bodies) {
    EXPECT_TRUE(hamel::is_valid_identifier(b.name)) << b.name;
    EXPECT_TRUE(hamel::is_valid_identifier(b.joint)) << b.joint;
    EXPECT_TRUE(bodies.insert(b.name).second) << b.name;
    EXPECT_TRUE(symbols.insert(b.joint).second) << b.joint;
  }
  ASSERT_EQ(t.inputs.size(), 2u);
  for (const std::string& u : t.inputs) {
    EXPECT_TRUE(hamel::is_valid_identifier(u)) << u;
    EXPECT_TRUE(symbols.insert(u).second) << u;
  }
  EXPECT_TRUE(bodies.count("x")) << "'_x' keeps its letters";
  EXPECT_TRUE(symbols.count("a_b")) << "'a::b' becomes a_b";
  EXPECT_TRUE(bodies.count("int_") && bodies.count("int_2")) << "a keyword, then its twin";
  EXPECT_TRUE(symbols.count("x_dot_")) << "'_dot' is reserved for rates";
  EXPECT_NO_THROW(hamel::load_model_from_text(hamel::tree_model_yaml(t), path));
}

}  // namespace
