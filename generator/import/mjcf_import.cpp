// MJCF through MuJoCo's own compiler: mj_loadXML, then the compiled mjModel is read (body frames at qpos0,
// joint anchors and axes, masses and inertias including those MuJoCo infers from geoms, armature, damping,
// stiffness with its spring reference, gravity, motor gears). Kinematics as MuJoCo's mj_kinematics: the
// joints of a body act in order, each in the frame the previous ones left; a hinge turns the body about its
// anchor, x ↦ T(anchor) Rot(axis, q − qpos0) T(−anchor) x.
#include "import/import_common.hpp"

#include <mujoco/mujoco.h>

#include <map>
#include <memory>

namespace hamel {

using namespace import_detail;

namespace {

std::string mj_name(const mjModel* m, int type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? n : "";
}

std::string element(const char* kind, const std::string& name, int id) {
  return std::string(kind) + " " + (name.empty() ? "#" + std::to_string(id) : "'" + name + "'");
}

// What hamel's tree format has no place for: tendons, equality constraints, contacts, fluid forces. Each is an
// error, or left out with a warning when its category is in --ignore.
template <class At>
void check_unsupported(const mjModel* m, Gate& gate, const At& at, const std::string& path) {
  for (int i = 0; i < m->ntendon; ++i) {
    const std::string n = mj_name(m, mjOBJ_TENDON, i);
    gate.check("tendons", at(n), element("tendon", n, i), "tendons are not part of hamel's tree format");
  }
  for (int i = 0; i < m->neq; ++i) {
    const std::string n = mj_name(m, mjOBJ_EQUALITY, i);
    gate.check("equality", at(n), element("equality constraint", n, i),
               "equality constraints (closed loops, welds) are not part of hamel's tree format");
  }
  if (!(m->opt.disableflags & mjDSBL_CONTACT))
    for (int i = 0; i < m->ngeom; ++i)
      if (m->geom_contype[i] || m->geom_conaffinity[i]) {
        const std::string n = mj_name(m, mjOBJ_GEOM, i);
        gate.check("contacts", at(n), element("geom", n, i) + " (contacts)",
                   "it can collide (contype/conaffinity), and hamel's trees have no contact model");
        break;
      }
  if (m->opt.density != 0 || m->opt.viscosity != 0 || m->opt.wind[0] != 0 || m->opt.wind[1] != 0 || m->opt.wind[2] != 0)
    gate.check("fluid", SourceLocation{path, 0, 0}, "option density/viscosity/wind",
               "fluid forces are not part of hamel's tree format");
}

// Gravity, in the world frame: the tree's on a fixed base, and on a floating base resolved in the base's frame as the
// state's Γ (docs/model-format.md); left out only under --ignore gravity.
void set_gravity(const mjModel* m, const ImportOptions& options, const Warn& warn, ImportedTree& t) {
  const double* g = m->opt.gravity;
  const bool gravity = !(m->opt.disableflags & mjDSBL_GRAVITY) && (g[0] != 0 || g[1] != 0 || g[2] != 0);
  if (!gravity) return;
  if (options.ignore.count("gravity")) {
    warn("left out (--ignore gravity): option gravity");
    t.left_out.push_back("gravity");
    return;
  }
  for (int c = 0; c < 3; ++c) t.gravity[c] = g[c];
}

// Actuators: motors on joints (force = gear · gain · ctrl) become inputs driving their joint's body.
template <class At>
void add_motors(const mjModel* m, Gate& gate, const At& at, const Warn& warn,
                const std::map<int, std::size_t>& body_of_joint, std::set<std::string>& symbols, ImportedTree& t) {
  for (int a = 0; a < m->nu; ++a) {
    const std::string aname = mj_name(m, mjOBJ_ACTUATOR, a);
    const int j = m->actuator_trnid[2 * a];
    const bool motor = m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_dyntype[a] == mjDYN_NONE &&
                       m->actuator_gaintype[a] == mjGAIN_FIXED && m->actuator_biastype[a] == mjBIAS_NONE &&
                       m->jnt_type[j] != mjJNT_FREE;
    if (!motor) {
      gate.check("actuators", at(aname), element("actuator", aname, a),
                 "only motors on hinge or slide joints (force = gear * gain * ctrl) become inputs");
      continue;
    }
    const std::string jname = mj_name(m, mjOBJ_JOINT, j);
    const std::size_t body = body_of_joint.at(j);
    std::string input = identifier("u_" + (aname.empty() ? jname : aname), "u" + std::to_string(a), symbols);
    t.inputs.push_back(input);
    t.bodies[body].drives.emplace_back(input, m->actuator_gear[6 * a] * m->actuator_gainprm[mjNGAIN * a]);
    if (m->actuator_ctrllimited[a] && a == 0)
      warn("actuator control ranges (ctrlrange) are not applied: hamel's inputs are used as given");
  }
}

}  // namespace

ImportedTree import_mjcf(const std::string& path, const ImportOptions& options, const Warn& warn) {
  ImportedTree t;
  t.source = path;
  t.format = "MJCF, compiled by MuJoCo " + std::string(mj_versionString());
  char err[1000] = "";
  std::unique_ptr<mjModel, void (*)(mjModel*)> owned(mj_loadXML(path.c_str(), nullptr, err, sizeof err),
                                                     mj_deleteModel);
  const mjModel* m = owned.get();
  if (!m) throw InputError(SourceLocation{path, 0, 0}, "", std::string("MuJoCo cannot compile the file: ") + err);
  const std::string text = read_text(path);
  const auto at = [&](const std::string& name) { return locate(path, text, name); };
  Gate gate(options, warn, t);
  if (options.floating)
    throw InputError(SourceLocation{path, 0, 0}, "--floating",
                     "applies to URDF; in MJCF the root floats when its body has a <freejoint/>");

  std::string model_name = options.name;
  if (model_name.empty()) {
    std::set<std::string> none;
    model_name = identifier(m->names, "imported", none);  // the model's name comes first in names
  }
  std::string why;
  if (!is_valid_model_name(model_name, &why))
    throw InputError(SourceLocation{path, 0, 0}, "--name", quote(model_name) + ": " + why + "; choose one with --name");
  t.name = model_name;

  check_unsupported(m, gate, at, path);

  // Per MuJoCo body: the tree body it rides on (−1 base, −2 world) and its frame in that tree body's frame.
  std::vector<int> host(static_cast<std::size_t>(m->nbody), -2);
  std::vector<Frame> in_host(static_cast<std::size_t>(m->nbody));
  std::set<std::string> labels;                                            // body names
  std::set<std::string> symbols{"t", "wx", "wy", "wz", "vx", "vy", "vz"};  // coordinates and inputs
  std::map<int, std::size_t> body_of_joint;
  int free_body = -1;
  bool world_jointed = false;  // some joint hangs from the world: a fixed base
  for (int b = 1; b < m->nbody; ++b) {
    const std::size_t ub = static_cast<std::size_t>(b);
    const int parent = m->body_parentid[b];
    const std::string bname = mj_name(m, mjOBJ_BODY, b);
    Frame Y = compose(in_host[static_cast<std::size_t>(parent)],
                      from_quaternion(m->body_pos + 3 * b, m->body_quat[4 * b], m->body_quat[4 * b + 1],
                                      m->body_quat[4 * b + 2], m->body_quat[4 * b + 3]));
    host[ub] = host[static_cast<std::size_t>(parent)];
    in_host[ub] = Y;
    const int first = m->body_jntadr[b], count = m->body_jntnum[b];
    for (int k = 0; k < count; ++k) {
      const int j = first + k;
      const std::string jname = mj_name(m, mjOBJ_JOINT, j);
      const int type = m->jnt_type[j];
      const int dof = m->jnt_dofadr[j], qadr = m->jnt_qposadr[j];
      if (type == mjJNT_BALL)
        throw InputError(at(jname), element("joint", jname, j) + " (body '" + bname + "')",
                         "ball joints have three degrees of freedom; hamel's trees have one per joint (hinge, slide)");
      if (type == mjJNT_FREE) {
        if (parent != 0 || count != 1)
          throw InputError(at(jname), element("free joint", jname, j) + " (body '" + bname + "')",
                           "only a body hanging from the world by its only joint can float (the SE3 base)");
        if (free_body >= 0)
          throw InputError(at(jname), element("free joint", jname, j),
                           "a second floating body; hamel's trees have one floating base (body '" +
                               mj_name(m, mjOBJ_BODY, free_body) + "' floats already)");
        for (int d = 0; d < 6; ++d)
          if (m->dof_armature[dof + d] != 0 || m->dof_damping[dof + d] != 0 || m->jnt_stiffness[j] != 0 ||
              m->dof_frictionloss[dof + d] != 0)
            throw InputError(at(jname), element("free joint", jname, j),
                             "armature, damping, stiffness or friction on the floating base is not part of hamel's "
                             "tree format (forces act on the joints only)");
        free_body = b;
        t.floating = true;
        t.base_pose = Y;  // the free body's frame in the world at qpos0
        t.base_name = identifier(bname, "base", labels);
        host[ub] = -1;
        in_host[ub] = Frame{};
        continue;
      }
      if (m->jnt_limited[j])
        gate.check("limits", at(jname), element("joint", jname, j) + " (range)",
                   "joint limits are constraint forces that hamel's trees do not model");
      if (m->dof_frictionloss[dof] != 0)
        gate.check("friction", at(jname), element("joint", jname, j) + " (frictionloss)",
                   "dry joint friction is not part of hamel's tree format");
      ImportedBody ib;
      ib.parent = host[ub] >= 0 ? host[ub] : -1;
      ib.joint = identifier(jname, "q" + std::to_string(j), symbols);
      ib.name = identifier(k + 1 == count ? bname : bname + "_" + jname, "body" + std::to_string(b), labels);
      world_jointed = world_jointed || host[ub] == -2;
      ib.prismatic = type == mjJNT_SLIDE;
      const double* anchor = m->jnt_pos + 3 * j;
      ib.joint_frame = ib.prismatic ? Y : compose(Y, translation(anchor[0], anchor[1], anchor[2]));
      // The body frame in the new joint's frame: what the next joint of this body and the inertia are placed in.
      Y = in_host[ub] = ib.prismatic ? Frame{} : translation(-anchor[0], -anchor[1], -anchor[2]);
      for (int c = 0; c < 3; ++c) ib.axis[c] = m->jnt_axis[3 * j + c];
      // hamel's coordinate is MuJoCo's measured from qpos0 (the configuration the body frames describe).
      const double q0 = m->qpos0[qadr];
      if (q0 != 0) warn("joint '" + jname + "': its coordinate is measured from ref = " + std::to_string(q0));
      ib.armature = m->dof_armature[dof];
      ib.damping = m->dof_damping[dof];
      ib.stiffness = m->jnt_stiffness[j];
      ib.reference = m->qpos_spring[qadr] - q0;
      host[ub] = static_cast<int>(t.bodies.size());
      body_of_joint[j] = t.bodies.size();
      t.bodies.push_back(ib);
    }
    // Mass properties go to the tree body the MuJoCo body rides on (fixed bodies merge into their host).
    const int h = host[ub];
    if (h == -2) continue;  // static bodies of the world
    double d[3] = {m->body_inertia[3 * b], m->body_inertia[3 * b + 1], m->body_inertia[3 * b + 2]}, I[3][3];
    const Frame iframe = from_quaternion(m->body_ipos + 3 * b, m->body_iquat[4 * b], m->body_iquat[4 * b + 1],
                                         m->body_iquat[4 * b + 2], m->body_iquat[4 * b + 3]);
    rotate_diagonal(iframe.R, d, I);
    MassProperties& target = h == -1 ? t.base : t.bodies[static_cast<std::size_t>(h)].inertial;
    add_in_frame(target, in_host[ub], m->body_mass[b], iframe.p, I);
  }
  if (t.floating && world_jointed)
    throw InputError(at(mj_name(m, mjOBJ_BODY, free_body)), "body '" + t.base_name + "'",
                     "floats while other bodies hang from the world by joints; hamel's trees have one base");
  if (t.bodies.empty())
    throw InputError(SourceLocation{path, 0, 0}, "", "the model has no hinge or slide joints; nothing to import");

  set_gravity(m, options, warn, t);

  add_motors(m, gate, at, warn, body_of_joint, symbols, t);
  return t;
}

}  // namespace hamel
