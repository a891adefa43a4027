// MuJoCo and DART behind tools/peer-bench/peers.hpp.
//
// MuJoCo's free joint: qpos = (p, quat), qvel = (R v, w); back: ẇ = qacc_ang, v̇ = Rᵀ qacc_lin − w × v (as
// tools/mujoco-bench/bench.cpp). DART's FreeJoint: positions (rotation vector, p), velocities (w, v), the body
// twist in the body frame, which is hamel's u; its accelerations are u̇.
#include "peers.hpp"

#include <mujoco/mujoco.h>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/RevoluteJoint.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/WeldJoint.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace peer {
namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "peer-bench: %s\n", what.c_str());
  std::exit(2);
}

Eigen::Matrix3d quat_to_R(const double* q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

// Γ of hamel's state in the world frame: R Γ.
Eigen::Vector3d world_gravity(const Layout& layout, const State& s, const double* fallback) {
  if (!layout.gravity) return Eigen::Vector3d(fallback[0], fallback[1], fallback[2]);
  const double* G = s.x.data() + layout.n_joints();
  return quat_to_R(s.quat) * Eigen::Vector3d(G[0], G[1], G[2]);
}

mjModel* load_mjcf(const char* xml) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(xml, nullptr, err, sizeof err);
  if (!m) fail(std::string("cannot load ") + xml + ": " + err);
  return m;
}

int free_joint(const mjModel* m) {
  for (int j = 0; j < m->njnt; ++j)
    if (m->jnt_type[j] == mjJNT_FREE) {
      if (m->body_parentid[m->jnt_bodyid[j]] != 0) fail("the free joint's body is not a child of the world");
      return j;
    }
  fail("no free joint: peer-bench times floating robots");
}

int joint_by_name(const mjModel* m, const std::string& name) {
  const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  if (j < 0 || m->jnt_type[j] != mjJNT_HINGE) fail("no MuJoCo hinge named " + name);
  return j;
}

// The actuator of hamel's input: the same name or, as `hamel import` names inputs, u_<actuator>.
int actuator_by_input(const mjModel* m, const std::string& input) {
  int a = mj_name2id(m, mjOBJ_ACTUATOR, input.c_str());
  if (a < 0 && input.rfind("u_", 0) == 0) a = mj_name2id(m, mjOBJ_ACTUATOR, input.c_str() + 2);
  if (a < 0) fail("no MuJoCo actuator for input " + input);
  return a;
}

}  // namespace

State random_state(const Layout& layout, const double gravity_world[3], std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
  s.x.assign(static_cast<std::size_t>(layout.n_state), 0.0);
  s.in.assign(static_cast<std::size_t>(layout.n_inputs), 0.0);
  double norm = 0;
  for (double& c : s.quat) c = u(rng), norm += c * c;
  for (double& c : s.quat) c /= std::sqrt(norm);
  for (double& c : s.pos) c = u(rng);
  const int n = layout.n_joints();
  for (int i = 0; i < n; ++i) s.x[static_cast<std::size_t>(i)] = 1.5 * u(rng);
  if (layout.gravity) {
    const Eigen::Vector3d G =
        quat_to_R(s.quat).transpose() * Eigen::Vector3d(gravity_world[0], gravity_world[1], gravity_world[2]);
    for (int k = 0; k < 3; ++k) s.x[static_cast<std::size_t>(n + k)] = G[k];
  }
  for (int i = layout.n_coordinates; i < layout.n_state; ++i) s.x[static_cast<std::size_t>(i)] = u(rng);
  for (double& c : s.in) c = u(rng);
  return s;
}

// ---------------------------------------------------------------------------------------------------- MuJoCo

struct Mujoco::Impl {
  Layout layout;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  int qadr_free = 0, vadr_free = 0;
  std::vector<int> qadr, vadr;  // of hamel's joints, in hamel's order
  std::vector<int> act;         // actuator of each input
  struct Saved {
    std::vector<double> qpos, qvel, ctrl;
    double gravity[3];
  };
  Saved slots[2];
  double default_gravity[3];
  std::vector<double> a0, J, A, B, M;
};

Mujoco::Mujoco(const char* xml, const Layout& layout, bool zero_armature) : impl_(new Impl) {
  Impl& s = *impl_;
  s.layout = layout;
  s.m = load_mjcf(xml);
  s.m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_CONTACT;  // hamel has neither contacts nor limits
  if (zero_armature)
    for (int i = 0; i < s.m->nv; ++i) s.m->dof_armature[i] = 0;
  s.d = mj_makeData(s.m);
  std::copy(s.m->opt.gravity, s.m->opt.gravity + 3, s.default_gravity);
  const int f = free_joint(s.m);
  s.qadr_free = s.m->jnt_qposadr[f];
  s.vadr_free = s.m->jnt_dofadr[f];
  for (int i = 0; i < layout.n_joints(); ++i) {
    const int j = joint_by_name(s.m, layout.state_names[static_cast<std::size_t>(i)]);
    s.qadr.push_back(s.m->jnt_qposadr[j]);
    s.vadr.push_back(s.m->jnt_dofadr[j]);
  }
  if (s.m->nv != layout.n_velocities()) fail("MuJoCo's model has another number of velocities than hamel's");
  for (const auto& in : layout.input_names) s.act.push_back(actuator_by_input(s.m, in));
  const int nv = s.m->nv;
  s.a0.resize(static_cast<std::size_t>(nv));
  s.J.resize(static_cast<std::size_t>(nv * layout.n_state));
  s.A.resize(static_cast<std::size_t>(4 * nv * nv));
  s.B.resize(static_cast<std::size_t>(2 * nv * std::max(1, s.m->nu)));
  s.M.resize(static_cast<std::size_t>(nv * nv));
}

Mujoco::~Mujoco() {
  mj_deleteData(impl_->d);
  mj_deleteModel(impl_->m);
  delete impl_;
}

const double* Mujoco::gravity() const { return impl_->default_gravity; }

void Mujoco::set(const State& st) {
  Impl& s = *impl_;
  const Layout& L = s.layout;
  const int n = L.n_joints();
  mj_resetData(s.m, s.d);
  const Eigen::Matrix3d R = quat_to_R(st.quat);
  for (int k = 0; k < 3; ++k) s.d->qpos[s.qadr_free + k] = st.pos[k];
  for (int k = 0; k < 4; ++k) s.d->qpos[s.qadr_free + 3 + k] = st.quat[k];
  const double* u = st.x.data() + L.n_coordinates;
  const Eigen::Vector3d v = R * Eigen::Vector3d(u[3], u[4], u[5]);
  for (int k = 0; k < 3; ++k) {
    s.d->qvel[s.vadr_free + k] = v[k];
    s.d->qvel[s.vadr_free + 3 + k] = u[k];
  }
  for (int i = 0; i < n; ++i) {
    s.d->qpos[s.qadr[static_cast<std::size_t>(i)]] = st.x[static_cast<std::size_t>(i)];
    s.d->qvel[s.vadr[static_cast<std::size_t>(i)]] = u[6 + i];
  }
  for (std::size_t k = 0; k < s.act.size(); ++k) s.d->ctrl[s.act[k]] = st.in[k];
  const Eigen::Vector3d g = world_gravity(L, st, s.m->opt.gravity);
  for (int k = 0; k < 3; ++k) s.m->opt.gravity[k] = g[k];
}

void Mujoco::save(int slot) {
  Impl& s = *impl_;
  Impl::Saved& t = s.slots[slot];
  t.qpos.assign(s.d->qpos, s.d->qpos + s.m->nq);
  t.qvel.assign(s.d->qvel, s.d->qvel + s.m->nv);
  t.ctrl.assign(s.d->ctrl, s.d->ctrl + s.m->nu);
  std::copy(s.m->opt.gravity, s.m->opt.gravity + 3, t.gravity);
}

void Mujoco::restore(int slot) {
  Impl& s = *impl_;
  const Impl::Saved& t = s.slots[slot];
  std::copy(t.qpos.begin(), t.qpos.end(), s.d->qpos);
  std::copy(t.qvel.begin(), t.qvel.end(), s.d->qvel);
  std::copy(t.ctrl.begin(), t.ctrl.end(), s.d->ctrl);
  std::copy(t.gravity, t.gravity + 3, s.m->opt.gravity);
}

void Mujoco::forward() { mj_forward(impl_->m, impl_->d); }

void Mujoco::smooth() {
  mj_fwdPosition(impl_->m, impl_->d);
  mj_fwdVelocity(impl_->m, impl_->d);
  mj_fwdActuation(impl_->m, impl_->d);
  mj_fwdAcceleration(impl_->m, impl_->d);
}

namespace {
void mujoco_udot(const Mujoco::Impl& s, const double* qacc, double* udot) {
  const Layout& L = s.layout;
  const Eigen::Matrix3d R = quat_to_R(s.d->qpos + s.qadr_free + 3);
  const double* qvel = s.d->qvel;
  const Eigen::Vector3d w(qvel[s.vadr_free + 3], qvel[s.vadr_free + 4], qvel[s.vadr_free + 5]);
  const Eigen::Vector3d v =
      R.transpose() * Eigen::Vector3d(qvel[s.vadr_free], qvel[s.vadr_free + 1], qvel[s.vadr_free + 2]);
  const Eigen::Vector3d vdot =
      R.transpose() * Eigen::Vector3d(qacc[s.vadr_free], qacc[s.vadr_free + 1], qacc[s.vadr_free + 2]) - w.cross(v);
  for (int k = 0; k < 3; ++k) {
    udot[k] = qacc[s.vadr_free + 3 + k];
    udot[3 + k] = vdot[k];
  }
  for (int i = 0; i < L.n_joints(); ++i) udot[6 + i] = qacc[s.vadr[static_cast<std::size_t>(i)]];
}
}  // namespace

void Mujoco::accelerations(double* udot) { mujoco_udot(*impl_, impl_->d->qacc, udot); }
void Mujoco::smooth_accelerations(double* udot) { mujoco_udot(*impl_, impl_->d->qacc_smooth, udot); }

void Mujoco::mass_matrix() {
  Impl& s = *impl_;
  mj_kinematics(s.m, s.d);
  mj_comPos(s.m, s.d);
  mj_crb(s.m, s.d);
  mj_fullM(s.m, s.M.data(), s.d->qM);
}

void Mujoco::mass_matrix_hamel(double* M) {
  // qvel = T u: qvel_lin = R v, qvel_ang = w, joints by name; M_hamel = Tᵀ M T.
  Impl& s = *impl_;
  const int nv = s.m->nv, n = s.layout.n_joints();
  const Eigen::Matrix3d R = quat_to_R(s.d->qpos + s.qadr_free + 3);
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(nv, nv);
  T.block(s.vadr_free, 3, 3, 3) = R;
  T.block(s.vadr_free + 3, 0, 3, 3) = Eigen::Matrix3d::Identity();
  for (int i = 0; i < n; ++i) T(s.vadr[static_cast<std::size_t>(i)], 6 + i) = 1;
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Mmj(s.M.data(), nv,
                                                                                                     nv);
  const Eigen::MatrixXd Mh = T.transpose() * Mmj * T;
  for (int r = 0; r < nv; ++r)
    for (int c = 0; c < nv; ++c) M[r * nv + c] = Mh(r, c);
}

void Mujoco::jacobian_fd() {
  // As mjd_transitionFD does, the position stage is skipped where only velocities (or gravity) change; those
  // columns come first, while the position stage holds the unperturbed state. Columns in hamel's order.
  Impl& s = *impl_;
  const double h = 1e-7;
  const int nv = s.m->nv, n = static_cast<int>(s.qadr.size()), G = s.layout.gravity ? 3 : 0;
  mj_forwardSkip(s.m, s.d, mjSTAGE_NONE, 1);
  std::copy(s.d->qacc, s.d->qacc + nv, s.a0.begin());
  auto column = [&](int c) {
    double* col = s.J.data() + static_cast<std::ptrdiff_t>(c) * nv;
    for (int k = 0; k < nv; ++k) col[k] = (s.d->qacc[k] - s.a0[static_cast<std::size_t>(k)]) / h;
  };
  for (int k = 0; k < G; ++k) {
    const double g = s.m->opt.gravity[k];
    s.m->opt.gravity[k] = g + h;
    mj_forwardSkip(s.m, s.d, mjSTAGE_POS, 1);
    column(n + k);
    s.m->opt.gravity[k] = g;
  }
  for (int k = 0; k < nv; ++k) {
    const double v = s.d->qvel[k];
    s.d->qvel[k] = v + h;
    mj_forwardSkip(s.m, s.d, mjSTAGE_POS, 1);
    column(n + G + k);
    s.d->qvel[k] = v;
  }
  for (int i = 0; i < n; ++i) {
    const int adr = s.qadr[static_cast<std::size_t>(i)];
    const double q = s.d->qpos[adr];
    s.d->qpos[adr] = q + h;
    mj_forwardSkip(s.m, s.d, mjSTAGE_NONE, 1);
    column(i);
    s.d->qpos[adr] = q;
  }
}

void Mujoco::transition_fd() {
  Impl& s = *impl_;
  mjd_transitionFD(s.m, s.d, 1e-6, 1, s.A.data(), s.m->nu ? s.B.data() : nullptr, nullptr, nullptr);
}

// ------------------------------------------------------------------------------------------------------ DART

namespace dd = dart::dynamics;

struct Dart::Impl {
  Layout layout;
  dd::SkeletonPtr skel;
  dd::FreeJoint* root = nullptr;
  std::vector<int> dof;                       // DART dof of each hamel joint
  std::vector<std::pair<int, double>> motor;  // per input: DART dof and gear
  Eigen::Vector3d default_gravity;
  struct Saved {
    Eigen::VectorXd q, v, f;
    Eigen::Vector3d g;
  };
  Saved slots[2];
  Eigen::VectorXd a0;
  Eigen::MatrixXd J;
  const Eigen::MatrixXd* M = nullptr;
};

namespace {

Eigen::Isometry3d pose(const double* pos, const double* quat) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = quat_to_R(quat);
  X.translation() = Eigen::Vector3d(pos[0], pos[1], pos[2]);
  return X;
}

Eigen::Isometry3d translation(const Eigen::Vector3d& t) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = t;
  return X;
}

}  // namespace

Dart::Dart(const char* xml, const Layout& layout, bool zero_armature) : impl_(new Impl) {
  Impl& s = *impl_;
  s.layout = layout;
  mjModel* m = load_mjcf(xml);
  s.default_gravity = Eigen::Vector3d(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]);
  s.skel = dd::Skeleton::create("peer");
  // Each MuJoCo body b ends in a DART BodyNode last[b] whose frame is b's frame moved to its last hinge's
  // anchor: b's frame = last[b]'s frame · tail[b]. A hinge rotates b's frame about its anchor a (in b's frame):
  // frame · T(a) R(axis, q) T(−a), composed in the order the joints are listed (mj_kinematics).
  std::vector<dd::BodyNode*> last(static_cast<std::size_t>(m->nbody), nullptr);
  std::vector<Eigen::Isometry3d> tail(static_cast<std::size_t>(m->nbody), Eigen::Isometry3d::Identity());
  for (int b = 1; b < m->nbody; ++b) {
    const int parent = m->body_parentid[b];
    dd::BodyNode* node = parent == 0 ? nullptr : last[static_cast<std::size_t>(parent)];
    Eigen::Isometry3d X = tail[static_cast<std::size_t>(parent)] * pose(m->body_pos + 3 * b, m->body_quat + 4 * b);
    const int nj = m->body_jntnum[b], j0 = m->body_jntadr[b];
    const std::string name = mj_id2name(m, mjOBJ_BODY, b) ? mj_id2name(m, mjOBJ_BODY, b) : "body" + std::to_string(b);
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
    if (nj == 0) {
      dd::WeldJoint::Properties p;
      p.mName = name + "_weld";
      p.mT_ParentBodyToJoint = X;
      node = s.skel->createJointAndBodyNodePair<dd::WeldJoint>(node, p, dd::BodyNode::AspectProperties(name)).second;
    } else if (m->jnt_type[j0] == mjJNT_FREE) {
      if (parent != 0 || nj != 1) fail("a free joint must be the only joint of a child of the world");
      auto pair = s.skel->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, dd::FreeJoint::Properties(),
                                                                    dd::BodyNode::AspectProperties(name));
      s.root = pair.first;
      node = pair.second;
    } else {
      for (int k = 0; k < nj; ++k) {
        const int j = j0 + k;
        if (m->jnt_type[j] != mjJNT_HINGE) fail("peer-bench: only hinge joints below the free joint");
        if (m->qpos0[m->jnt_qposadr[j]] != 0) fail("peer-bench: hinge with a nonzero ref");
        const int v = m->jnt_dofadr[j];
        if (m->dof_armature[v] != 0 && !zero_armature) fail("DART 6.12 has no joint armature");
        const Eigen::Vector3d a(m->jnt_pos[3 * j], m->jnt_pos[3 * j + 1], m->jnt_pos[3 * j + 2]);
        dd::RevoluteJoint::Properties p;
        p.mName = mj_id2name(m, mjOBJ_JOINT, j);
        p.mAxis = Eigen::Vector3d(m->jnt_axis[3 * j], m->jnt_axis[3 * j + 1], m->jnt_axis[3 * j + 2]);
        p.mT_ParentBodyToJoint = (k == 0 ? X : Eigen::Isometry3d::Identity()) * translation(a - anchor);
        p.mSpringStiffnesses[0] = m->jnt_stiffness[j];
        p.mRestPositions[0] = m->qpos_spring[m->jnt_qposadr[j]];
        p.mDampingCoefficients[0] = m->dof_damping[v];
        anchor = a;
        const std::string node_name = k + 1 == nj ? name : name + "_" + p.mName;
        node = s.skel->createJointAndBodyNodePair<dd::RevoluteJoint>(node, p, dd::BodyNode::AspectProperties(node_name))
                   .second;
        if (k + 1 < nj) node->setInertia(dd::Inertia(0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero()));
      }
    }
    tail[static_cast<std::size_t>(b)] = translation(-anchor);
    last[static_cast<std::size_t>(b)] = node;
    const Eigen::Matrix3d Q = quat_to_R(m->body_iquat + 4 * b);
    const Eigen::Vector3d d(m->body_inertia[3 * b], m->body_inertia[3 * b + 1], m->body_inertia[3 * b + 2]);
    const Eigen::Vector3d com =
        Eigen::Vector3d(m->body_ipos[3 * b], m->body_ipos[3 * b + 1], m->body_ipos[3 * b + 2]) - anchor;
    node->setInertia(dd::Inertia(m->body_mass[b], com, Q * d.asDiagonal() * Q.transpose()));
  }
  if (!s.root) fail("no free joint: peer-bench times floating robots");
  // Joint springs and dampers are implicit in DART's articulated-body recursion over one time step; a step of
  // 1e-30 s makes them explicit (h·d and h²·k vanish next to the inertias).
  s.skel->setTimeStep(1e-30);
  for (int i = 0; i < layout.n_joints(); ++i) {
    const std::string& nm = layout.state_names[static_cast<std::size_t>(i)];
    dd::Joint* jt = s.skel->getJoint(nm);
    if (!jt) fail("no DART joint " + nm);
    s.dof.push_back(static_cast<int>(jt->getIndexInSkeleton(0)));
  }
  for (const auto& in : layout.input_names) {
    const int a = actuator_by_input(m, in);
    if (m->actuator_trntype[a] != mjTRN_JOINT || m->actuator_dyntype[a] != mjDYN_NONE ||
        m->actuator_gaintype[a] != mjGAIN_FIXED || m->actuator_biastype[a] != mjBIAS_NONE ||
        m->actuator_gainprm[a * mjNGAIN] != 1)
      fail("peer-bench: only motors on joints (force = gear · ctrl)");
    const char* jn = mj_id2name(m, mjOBJ_JOINT, m->actuator_trnid[2 * a]);
    s.motor.emplace_back(static_cast<int>(s.skel->getJoint(jn)->getIndexInSkeleton(0)), m->actuator_gear[6 * a]);
  }
  mj_deleteModel(m);
  const auto nd = static_cast<Eigen::Index>(s.skel->getNumDofs());
  if (nd != layout.n_velocities()) fail("DART's skeleton has another number of velocities than hamel's");
  s.J.resize(nd, layout.n_state);
}

Dart::~Dart() { delete impl_; }

void Dart::set(const State& st) {
  Impl& s = *impl_;
  const Layout& L = s.layout;
  const auto nd = static_cast<Eigen::Index>(s.skel->getNumDofs());
  Eigen::VectorXd q = Eigen::VectorXd::Zero(nd), v = Eigen::VectorXd::Zero(nd), f = Eigen::VectorXd::Zero(nd);
  const Eigen::Index r = static_cast<Eigen::Index>(s.root->getIndexInSkeleton(0));
  q.segment<6>(r) = dd::FreeJoint::convertToPositions(pose(st.pos, st.quat));
  const double* u = st.x.data() + L.n_coordinates;
  for (int k = 0; k < 6; ++k) v[r + k] = u[k];
  for (int i = 0; i < L.n_joints(); ++i) {
    q[s.dof[static_cast<std::size_t>(i)]] = st.x[static_cast<std::size_t>(i)];
    v[s.dof[static_cast<std::size_t>(i)]] = u[6 + i];
  }
  for (std::size_t k = 0; k < s.motor.size(); ++k) f[s.motor[k].first] += s.motor[k].second * st.in[k];
  s.skel->setPositions(q);
  s.skel->setVelocities(v);
  s.skel->setForces(f);
  s.skel->setGravity(world_gravity(L, st, s.default_gravity.data()));
}

void Dart::save(int slot) {
  Impl& s = *impl_;
  s.slots[slot] = {s.skel->getPositions(), s.skel->getVelocities(), s.skel->getForces(), s.skel->getGravity()};
}

void Dart::restore(int slot) {
  Impl& s = *impl_;
  const Impl::Saved& t = s.slots[slot];
  s.skel->setPositions(t.q);
  s.skel->setVelocities(t.v);
  s.skel->setForces(t.f);
  s.skel->setGravity(t.g);
}

void Dart::forward() { impl_->skel->computeForwardDynamics(); }

void Dart::accelerations(double* udot) {
  Impl& s = *impl_;
  const Eigen::VectorXd& a = s.skel->getAccelerations();
  const Eigen::Index r = static_cast<Eigen::Index>(s.root->getIndexInSkeleton(0));
  for (int k = 0; k < 6; ++k) udot[k] = a[r + k];
  for (int i = 0; i < s.layout.n_joints(); ++i) udot[6 + i] = a[s.dof[static_cast<std::size_t>(i)]];
}

void Dart::mass_matrix() { impl_->M = &impl_->skel->getMassMatrix(); }

void Dart::mass_matrix_hamel(double* M) {
  Impl& s = *impl_;
  const int nv = s.layout.n_velocities(), n = s.layout.n_joints();
  std::vector<int> idx(static_cast<std::size_t>(nv));
  const int r = static_cast<int>(s.root->getIndexInSkeleton(0));
  for (int k = 0; k < 6; ++k) idx[static_cast<std::size_t>(k)] = r + k;
  for (int i = 0; i < n; ++i) idx[static_cast<std::size_t>(6 + i)] = s.dof[static_cast<std::size_t>(i)];
  for (int a = 0; a < nv; ++a)
    for (int b = 0; b < nv; ++b)
      M[a * nv + b] = (*s.M)(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]);
}

void Dart::jacobian_fd() {
  Impl& s = *impl_;
  const double h = 1e-7;
  dd::Skeleton& sk = *s.skel;
  sk.computeForwardDynamics();
  s.a0 = sk.getAccelerations();
  Eigen::Index c = 0;
  for (int i : s.dof) {
    const double q = sk.getPosition(static_cast<std::size_t>(i));
    sk.setPosition(static_cast<std::size_t>(i), q + h);
    sk.computeForwardDynamics();
    s.J.col(c++) = (sk.getAccelerations() - s.a0) / h;
    sk.setPosition(static_cast<std::size_t>(i), q);
  }
  if (s.layout.gravity)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d g = sk.getGravity();
      Eigen::Vector3d gp = g;
      gp[k] += h;
      sk.setGravity(gp);
      sk.computeForwardDynamics();
      s.J.col(c++) = (sk.getAccelerations() - s.a0) / h;
      sk.setGravity(g);
    }
  const auto nd = static_cast<std::size_t>(sk.getNumDofs());
  for (std::size_t i = 0; i < nd; ++i) {
    const double v = sk.getVelocity(i);
    sk.setVelocity(i, v + h);
    sk.computeForwardDynamics();
    s.J.col(c++) = (sk.getAccelerations() - s.a0) / h;
    sk.setVelocity(i, v);
  }
}

}  // namespace peer
