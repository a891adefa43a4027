// MJCF through MuJoCo's own compiler: mj_loadXML, then the compiled mjModel is read (body frames at qpos0,
// joint anchors and axes, masses and inertias including those MuJoCo infers from geoms, armature, damping,
// stiffness with its spring reference, gravity, motor gears). Kinematics as MuJoCo's mj_kinematics: the
// joints of a body act in order, each in the frame the previous ones left; a hinge turns the body about its
// anchor, x ↦ T(anchor) Rot(axis, q − qpos0) T(−anchor) x.
#include "import/import_common.hpp"
#include "report/atomic_file.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <vector>

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

// The values of attribute `name` (name="..." or name='...') in an XML text, in order.
std::vector<std::string> attribute_values(const std::string& text, const std::string& name) {
  std::vector<std::string> out;
  const std::string key = name + "=";
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1)) {
    if (at > 0 && (std::isalnum(static_cast<unsigned char>(text[at - 1])) || text[at - 1] == '_')) continue;
    const std::size_t open = at + key.size();
    if (open >= text.size() || (text[open] != '"' && text[open] != '\'')) continue;
    const std::size_t close = text.find(text[open], open + 1);
    if (close == std::string::npos) break;
    out.push_back(text.substr(open + 1, close - open - 1));
  }
  return out;
}

// MuJoCo opens the files an MJCF file names itself (includes, meshes, textures), and would read a device or block on
// a FIFO: every file named by a file="..." attribute, looked up where MuJoCo looks (the model's folder and its
// meshdir, texturedir and assetdir), in the main file and the files it includes, is checked as the robot file is
// (model/input_file.hpp) before MuJoCo sees any of them, and recorded as an input of the run (note_input_file).
void check_mjcf_files(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(path).parent_path();
  std::set<std::string> seen{path};
  std::vector<std::string> texts{read_text(path)};
  std::vector<fs::path> dirs{folder};
  for (std::size_t i = 0; i < texts.size(); ++i) {
    for (const char* attribute : {"meshdir", "texturedir", "assetdir"})
      for (const std::string& d : attribute_values(texts[i], attribute)) dirs.push_back(folder / d);
    for (const std::string& file : attribute_values(texts[i], "file")) {
      if (file.empty()) continue;
      for (const fs::path& dir : dirs) {
        const std::string candidate = (fs::path(file).is_absolute() ? fs::path(file) : dir / file).string();
        std::error_code ec;
        if (!fs::exists(fs::symlink_status(candidate, ec)) || !seen.insert(candidate).second) continue;
        check_input_file(candidate, "robot file", kMaxRobotFileBytes);
        // An input of this run like the robot file itself: no output (import's -o) may replace it.
        note_input_file(candidate, "a file the robot file names (file=\"" + file + "\")");
        const std::string lower = [&] {
          std::string s = candidate;
          for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
          return s;
        }();
        if (lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".xml") == 0) texts.push_back(read_text(candidate));
      }
    }
  }
}

// What hamel's tree format has no place for: tendons, equality constraints, contacts, fluid forces. Each is an
// error, or left out with a warning when its category is in --ignore.
template <class At>
void check_unsupported(const mjModel* m, Gate& gate, const At& at, const std::string& path) {
  for (int i = 0; i < m->ntendon; ++i) {
    const std::string n = mj_name(m, mjOBJ_TENDON, i);
    gate.check("tendons", at(n, {"spatial", "fixed"}), element("tendon", n, i),
               "tendons are not part of hamel's tree format");
  }
  for (int i = 0; i < m->neq; ++i) {
    if (m->eq_type[i] == mjEQ_CONNECT || m->eq_type[i] == mjEQ_WELD) continue;  // closed loops (add_loops)
    const std::string n = mj_name(m, mjOBJ_EQUALITY, i);
    gate.check("equality", at(n, {"joint", "tendon", "flex", "distance"}), element("equality constraint", n, i),
               "equality constraints on joints and tendons are not part of hamel's tree format (connect and weld "
               "are: closed loops)");
  }
  if (!(m->opt.disableflags & mjDSBL_CONTACT))
    for (int i = 0; i < m->ngeom; ++i)
      if (m->geom_contype[i] || m->geom_conaffinity[i]) {
        const std::string n = mj_name(m, mjOBJ_GEOM, i);
        gate.check("contacts", at(n, {"geom"}), element("geom", n, i) + " (contacts)",
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
      gate.check("actuators",
                 at(aname, {"motor", "position", "velocity", "general", "muscle", "cylinder", "damper", "adhesion",
                            "intvelocity", "plugin"}),
                 element("actuator", aname, a),
                 "only motors on hinge or slide joints (force = gear * gain * ctrl) become inputs");
      continue;
    }
    const std::string jname = mj_name(m, mjOBJ_JOINT, j);
    if (!body_of_joint.count(j)) continue;  // its joint was refused (a ball joint): reported with it
    const std::size_t body = body_of_joint.at(j);
    std::string input = identifier("u_" + (aname.empty() ? jname : aname), "u" + std::to_string(a), symbols);
    t.inputs.push_back(input);
    t.bodies[body].drives.emplace_back(input, m->actuator_gear[6 * a] * m->actuator_gainprm[mjNGAIN * a]);
    if (m->actuator_ctrllimited[a] && a == 0)
      warn("actuator control ranges (ctrlrange) are not applied: hamel's inputs are used as given");
  }
}

// x ↦ X x of a point.
void transform(const Frame& X, const double* x, double out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = X.p[r] + X.R[r][0] * x[0] + X.R[r][1] * x[1] + X.R[r][2] * x[2];
}

// <equality> connect and weld as closed loops (model key `loops`), on a fixed base. MuJoCo's compiled data, each in
// its body's frame at qpos0 (where the constraint holds by definition): connect, the anchor in body1 (eq_data 0..2) and
// the same point in body2 (3..5); weld, the anchor in body2 (0..2), the same point in body1 (3..5) and body2's
// orientation in body1's frame (quaternion, 6..9). A body rides on the tree body `host` (−2: the world) with its frame
// `in_host` in that body's frame; `names` are the tree bodies' names.
template <class At>
void add_loops(const mjModel* m, const ImportOptions& options, Gate& gate, const At& at, const Warn& warn,
               const std::vector<int>& host, const std::vector<Frame>& in_host, std::set<std::string>& symbols,
               ImportedTree& t) {
  for (int i = 0; i < m->neq; ++i) {
    const bool weld = m->eq_type[i] == mjEQ_WELD;
    if (m->eq_type[i] != mjEQ_CONNECT && !weld) continue;
    const std::string n = mj_name(m, mjOBJ_EQUALITY, i);
    const std::string what = element(weld ? "weld" : "connect", n, i);
    if (options.ignore.count("equality")) {  // cut open, with a warning
      gate.check("equality", at(n), what, "");
      continue;
    }
    if (!m->eq_active[i]) {
      warn("left out: " + what + " is inactive (active=\"false\")");
      continue;
    }
    if (t.floating) {  // refused with everything else hamel has no place for (Gate)
      gate.refuse(at(n), what,
                  "closed loops are supported on trees fixed to the world; this model's base floats (a "
                  "<freejoint/>); pass --ignore equality to cut the loop open");
      continue;
    }
    const double* data = m->eq_data + static_cast<std::size_t>(i) * mjNEQDATA;
    int b1 = m->eq_obj1id[i], b2 = m->eq_obj2id[i];
    double a1[3], a2[3];  // the two points in their bodies' frames
    double R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if (weld) {
      for (int c = 0; c < 3; ++c) a1[c] = data[3 + c], a2[c] = data[c];
      const double zero[3] = {0, 0, 0};
      const Frame q = from_quaternion(zero, data[6], data[7], data[8], data[9]);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R[r][c] = q.R[r][c];
    } else {
      for (int c = 0; c < 3; ++c) a1[c] = data[c], a2[c] = data[3 + c];
    }
    const int h1 = host[static_cast<std::size_t>(b1)], h2 = host[static_cast<std::size_t>(b2)];
    if (h1 == h2) {
      gate.refuse(at(n), what,
                  "both bodies ride on the same " + std::string(h1 == -2 ? "world" : "tree body") +
                      ": the constraint holds nothing, or nothing but a rigid body; expected bodies that move "
                      "relative to each other");
      continue;
    }
    ImportedLoop loop;
    loop.name = identifier(n, "loop" + std::to_string(i), symbols);
    for (const char* suffix : {"_x", "_y", "_z", "_rx", "_ry", "_rz"}) symbols.insert(loop.name + suffix);
    loop.weld = weld;
    // The loader's `body` is a moving body: with the world as body1, the ends swap (the same constraint).
    bool swap = h1 == -2;
    const int hb = swap ? h2 : h1, ht = swap ? h1 : h2;
    const Frame& Xb = in_host[static_cast<std::size_t>(swap ? b2 : b1)];
    const Frame& Xt = in_host[static_cast<std::size_t>(swap ? b1 : b2)];
    loop.body = t.bodies[static_cast<std::size_t>(hb)].name;
    loop.to = ht == -2 ? "world" : t.bodies[static_cast<std::size_t>(ht)].name;
    transform(Xb, swap ? a2 : a1, loop.point);
    transform(Xt, swap ? a1 : a2, loop.to_point);
    // Frames: body1's is R (body2's orientation at qpos0) in body1, body2's its own axes.
    double F1[3][3], F2[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        F1[r][c] = 0;
        for (int k = 0; k < 3; ++k) F1[r][c] += in_host[static_cast<std::size_t>(b1)].R[r][k] * R[k][c];
        F2[r][c] = in_host[static_cast<std::size_t>(b2)].R[r][c];
      }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        loop.rotation[r][c] = swap ? F2[r][c] : F1[r][c];
        loop.to_rotation[r][c] = swap ? F1[r][c] : F2[r][c];
      }
    t.loops.push_back(loop);
  }
}

}  // namespace

ImportedTree import_mjcf(const std::string& path, const ImportOptions& options, const Warn& warn) {
  ImportedTree t;
  t.source = path;
  t.format = "MJCF, compiled by MuJoCo " + std::string(mj_versionString());
  check_mjcf_files(path);
  char err[1000] = "";
  std::unique_ptr<mjModel, void (*)(mjModel*)> owned(mj_loadXML(path.c_str(), nullptr, err, sizeof err),
                                                     mj_deleteModel);
  const mjModel* m = owned.get();
  if (!m) throw InputError(SourceLocation{path, 0, 0}, "", std::string("MuJoCo cannot compile the file: ") + err);
  const std::string text = read_text(path);
  const Locator at(path, text);
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
  std::vector<std::string> world_jointed;  // bodies whose joint hangs from the world: a fixed base
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
      if (type == mjJNT_BALL) {
        gate.refuse(at(jname, {"joint", "freejoint"}), element("joint", jname, j) + " (body '" + bname + "')",
                    "ball joints have three degrees of freedom; hamel's trees have one per joint (hinge, slide)");
        continue;
      }
      if (type == mjJNT_FREE) {
        if (parent != 0 || count != 1)
          throw InputError(at(jname, {"joint", "freejoint"}),
                           element("free joint", jname, j) + " (body '" + bname + "')",
                           "only a body hanging from the world by its only joint can float (the SE3 base)");
        if (free_body >= 0)
          throw InputError(at(jname, {"joint", "freejoint"}), element("free joint", jname, j),
                           "a second floating body; hamel's trees have one floating base (body '" +
                               mj_name(m, mjOBJ_BODY, free_body) + "' floats already)");
        for (int d = 0; d < 6; ++d)
          if (m->dof_armature[dof + d] != 0 || m->dof_damping[dof + d] != 0 || m->jnt_stiffness[j] != 0 ||
              m->dof_frictionloss[dof + d] != 0)
            throw InputError(at(jname, {"joint", "freejoint"}), element("free joint", jname, j),
                             "armature, damping, stiffness or friction on the floating base is not part of hamel's "
                             "tree format (forces act on the joints only)");
        free_body = b;
        t.floating = true;
        t.base_pose = Y;  // the free body's frame in the world at qpos0
        t.base_where = at(bname);
        t.base_name = identifier(bname, "base", labels);
        host[ub] = -1;
        in_host[ub] = Frame{};
        continue;
      }
      if (m->jnt_limited[j])
        gate.check("limits", at(jname, {"joint", "freejoint"}), element("joint", jname, j) + " (range)",
                   "joint limits are constraint forces that hamel's trees do not model");
      if (m->dof_frictionloss[dof] != 0)
        gate.check("friction", at(jname, {"joint", "freejoint"}), element("joint", jname, j) + " (frictionloss)",
                   "dry joint friction is not part of hamel's tree format");
      ImportedBody ib;
      ib.where = at(jname);
      ib.what = element("joint", jname, j) + " (body '" + bname + "')";
      ib.parent = host[ub] >= 0 ? host[ub] : -1;
      ib.joint = identifier(jname, "q" + std::to_string(j), symbols);
      ib.name = identifier(k + 1 == count ? bname : bname + "_" + jname, "body" + std::to_string(b), labels);
      if (host[ub] == -2 && (world_jointed.empty() || world_jointed.back() != bname)) world_jointed.push_back(bname);
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
  // Actuators before anything else is decided: every element hamel has no place for goes into one message.
  add_motors(m, gate, at, warn, body_of_joint, symbols, t);
  add_loops(m, options, gate, at, warn, host, in_host, symbols, t);
  gate.finish();
  if (t.floating && !world_jointed.empty()) {
    std::string names;
    for (std::size_t k = 0; k < world_jointed.size() && k < 5; ++k) names += (k ? ", '" : "'") + world_jointed[k] + "'";
    if (world_jointed.size() > 5) names += " and " + std::to_string(world_jointed.size() - 5) + " more";
    throw InputError(at(mj_name(m, mjOBJ_BODY, free_body), {"body"}), "body '" + t.base_name + "'",
                     "floats (free joint) while " + names + (world_jointed.size() == 1 ? " hangs" : " hang") +
                         " from the world by hinge or slide joints; hamel's trees have one base, floating or "
                         "fixed. Expected one of: remove the free joint (the body is then fixed to the world and "
                         "the tree's base is the world), or move the world-jointed bodies under the floating body "
                         "(or into a model of their own), then import again");
  }
  if (t.bodies.empty())
    throw InputError(SourceLocation{path, 0, 0}, "", "the model has no hinge or slide joints; nothing to import");

  set_gravity(m, options, warn, t);
  t.gravity_where = SourceLocation{path, 0, 0};
  if (const std::size_t g = text.find("gravity="); g != std::string::npos) {
    const std::size_t line_start = text.rfind('\n', g) == std::string::npos ? 0 : text.rfind('\n', g) + 1;
    t.gravity_where.line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(g), '\n')) + 1;
    t.gravity_where.column = static_cast<int>(g - line_start) + 1;
  }

  return t;
}

}  // namespace hamel
