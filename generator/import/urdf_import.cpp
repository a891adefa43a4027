// URDF through urdfdom: links are bodies, each revolute, continuous or prismatic joint moves its child link
// as child frame = parent frame · origin · exp(q S) (URDF's convention is hamel's tree joint), fixed joints
// merge the child's inertia into the parent. The root link is the world (fixed base) or, with --floating,
// the SE3 floating base. Every moving joint gets an input tau_<joint>, its generalized force.
#include "import/import_common.hpp"

#include <urdf_parser/urdf_parser.h>

#include <tinyxml.h>
#include <charconv>
#include <map>
#include <set>
#include <vector>

namespace hamel {

using namespace import_detail;

namespace {

// A number as URDF writes it: a finite decimal, surrounded by blanks at most (no nan, inf, hex, or overflow).
bool parse_finite(const std::string& text, double& out) {
  const std::size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return false;
  const std::size_t end = text.find_last_not_of(" \t\r\n") + 1;
  const char* first = text.data() + begin;
  const char* last = text.data() + end;
  if (*first == '+') ++first;
  const auto r = std::from_chars(first, last, out);
  return r.ec == std::errc() && r.ptr == last && std::isfinite(out);
}

// urdfdom drops an <inertial> it cannot read (no <mass> or <inertia>, a value of nan, 1e400 or 0x10) with a
// message and keeps the link with mass 0 and inertia 0: a silently different robot. Each <inertial> is checked here
// first, and refused with its element's file:line.
void check_inertials(const std::string& path, const std::string& text) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  if (doc.Error()) return;  // urdfdom says what is wrong
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (!robot) return;
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    const std::string key = "link '" + std::string(name ? name : "") + "' <inertial>";
    for (const TiXmlElement* inertial = link->FirstChildElement("inertial"); inertial;
         inertial = inertial->NextSiblingElement("inertial")) {
      const auto at = [&](const TiXmlElement* e) { return SourceLocation{path, e->Row(), e->Column()}; };
      const auto number = [&](const TiXmlElement* e, const char* attribute, const std::string& what) {
        const char* v = e->Attribute(attribute);
        double x = 0;
        if (!v)
          throw InputError(at(e), key, "<" + e->ValueStr() + "> has no attribute " + attribute + "; expected " + what);
        if (!parse_finite(v, x))
          throw InputError(at(e), key,
                           "<" + e->ValueStr() + " " + attribute + "=" + quote(v) +
                               "> is not a finite decimal number; expected " + what);
        return x;
      };
      const TiXmlElement* mass = inertial->FirstChildElement("mass");
      if (!mass) throw InputError(at(inertial), key, "has no <mass value=...>; expected the link's mass");
      (void)number(mass, "value", "the link's mass");
      const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
      if (!inertia)
        throw InputError(at(inertial), key,
                         "has no <inertia ixx ixy ixz iyy iyz izz>; expected the link's inertia about its centre "
                         "of mass");
      for (const char* a : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
        (void)number(inertia, a, "a component of the inertia");
      if (const TiXmlElement* origin = inertial->FirstChildElement("origin"))
        for (const char* a : {"xyz", "rpy"})
          if (const char* v = origin->Attribute(a)) {
            std::istringstream words(v);
            std::string word;
            int count = 0;
            double x = 0;
            while (words >> word) {
              ++count;
              if (!parse_finite(word, x))
                throw InputError(at(origin), key,
                                 "<origin " + std::string(a) + "=" + quote(v) +
                                     "> holds something that is not a finite decimal number; expected three numbers");
            }
            if (count != 3)
              throw InputError(at(origin), key,
                               "<origin " + std::string(a) + "=" + quote(v) + "> does not hold three numbers");
          }
    }
  }
}

struct Walker {
  ImportedTree& t;
  const ImportOptions& options;
  const Warn& warn;
  const std::string& path;
  const Locator& locate;
  Gate& gate;
  std::set<std::string> labels, symbols{"t", "wx", "wy", "wz", "vx", "vy", "vz"};
  bool limits_warned = false;
  std::set<const urdf::Link*> placed;  ///< links already visited

  Frame pose(const urdf::Pose& p) const {
    const double x[3] = {p.position.x, p.position.y, p.position.z};
    return from_quaternion(x, p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  }

  // `host`: tree body index (−1 base, −2 world); `in_host`: the link's frame in the host's frame. Depth first, the
  // children of a link in order (the order of the tree's bodies), with a stack of its own: a chain of 10 000 links
  // overflowed the call stack when this recursed. A link reached twice (joints that form a cycle) is refused
  // (`placed` holds the root on entry).
  void visit(const urdf::LinkConstSharedPtr& root, int root_host, const Frame& root_in_host) {
    struct Pending {
      urdf::LinkConstSharedPtr link;
      int host;
      Frame in_host;
    };
    std::vector<Pending> stack;
    add_inertial(*root, root_host, root_in_host);
    push_children(root, root_host, root_in_host, stack);
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      const urdf::LinkConstSharedPtr& child = p.link;
      const urdf::JointSharedPtr& joint = child->parent_joint;
      const SourceLocation where = locate(joint->name, {"joint"});
      const std::string what = "joint '" + joint->name + "'";
      // A joint whose child is its parent, or joints that lead back to a link already placed, would loop
      // forever: a URDF is a tree.
      if (!placed.insert(child.get()).second)
        throw InputError(where, what,
                         "its child link '" + child->name +
                             "' is already reached from the root (the joints form a cycle, or the joint's parent is "
                             "its child); expected the joints to form a tree");
      const Frame origin = compose(p.in_host, pose(joint->parent_to_joint_origin_transform));
      if (joint->mimic)
        throw InputError(where, what, "mimic joints couple coordinates; hamel's tree joints are independent");
      switch (joint->type) {
        case urdf::Joint::FIXED:
          add_inertial(*child, p.host, origin);
          push_children(child, p.host, origin, stack);
          continue;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC:
          break;
        default:
          throw InputError(where, what,
                           "floating and planar joints have several degrees of freedom; hamel's tree joints have "
                           "one (a floating root: import with --floating)");
      }
      ImportedBody b;
      b.where = where;
      b.what = what;
      b.parent = p.host >= 0 ? p.host : -1;
      b.joint = identifier(joint->name, "q" + std::to_string(t.bodies.size() + 1), symbols);
      b.name = identifier(child->name, "link" + std::to_string(t.bodies.size() + 1), labels);
      b.prismatic = joint->type == urdf::Joint::PRISMATIC;
      const double a[3] = {joint->axis.x, joint->axis.y, joint->axis.z};
      const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      if (!(n > 0)) throw InputError(where, what + " axis", "expected a non-zero axis");
      for (int c = 0; c < 3; ++c) b.axis[c] = a[c] / n;
      b.joint_frame = origin;
      if (joint->dynamics) {
        b.damping = joint->dynamics->damping;
        if (joint->dynamics->friction != 0)
          gate.check("friction", where, what + " (dynamics friction)",
                     "dry joint friction is not part of hamel's tree format");
      }
      if (joint->limits && joint->type != urdf::Joint::CONTINUOUS && !limits_warned) {
        // URDF requires <limit> on revolute and prismatic joints (effort and velocity too), so position
        // limits are noted rather than refused.
        warn("joint position limits (<limit lower upper>) are not modelled; the joints move freely");
        limits_warned = true;
      }
      const std::string input = identifier("tau_" + b.joint, "tau" + std::to_string(t.bodies.size() + 1), symbols);
      t.inputs.push_back(input);
      b.drives.emplace_back(input, 1.0);
      const int index = static_cast<int>(t.bodies.size());
      t.bodies.push_back(b);
      add_inertial(*child, index, Frame{});
      push_children(child, index, Frame{}, stack);
    }
  }

  // The children of `link`, last first: popped, they are taken in order.
  template <class Stack>
  static void push_children(const urdf::LinkConstSharedPtr& link, int host, const Frame& in_host, Stack& stack) {
    for (auto it = link->child_links.rbegin(); it != link->child_links.rend(); ++it)
      stack.push_back({*it, host, in_host});
  }

  void add_inertial(const urdf::Link& link, int host, const Frame& in_host) {
    if (!link.inertial || host == -2) return;
    const urdf::Inertial& in = *link.inertial;
    const Frame f = pose(in.origin);
    const double local[3][3] = {{in.ixx, in.ixy, in.ixz}, {in.ixy, in.iyy, in.iyz}, {in.ixz, in.iyz, in.izz}};
    double I[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        I[i][j] = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) I[i][j] += f.R[i][k] * local[k][l] * f.R[j][l];
      }
    MassProperties& target = host == -1 ? t.base : t.bodies[static_cast<std::size_t>(host)].inertial;
    add_in_frame(target, in_host, in.mass, f.p, I);
  }
};

}  // namespace

ImportedTree import_urdf(const std::string& path, const ImportOptions& options, const Warn& warn) {
  ImportedTree t;
  t.source = path;
  t.format = "URDF, read by urdfdom";
  const std::string text = read_text(path);
  if (text.empty()) throw InputError(SourceLocation{path, 0, 0}, "", "cannot read the file (or it is empty)");
  check_inertials(path, text);
  // A joint that names one link as parent and child: urdfdom accepts it and links the link to itself. A link that
  // is the child of two joints (joints that form a cycle): urdfdom links it into a cycle of shared pointers, which
  // leak. Both refused before urdfdom reads the file.
  {
    TiXmlDocument doc;
    doc.Parse(text.c_str());
    std::map<std::string, std::string> child_of;  // link → the first joint that names it as child
    if (const TiXmlElement* robot = doc.Error() ? nullptr : doc.FirstChildElement("robot"))
      for (const TiXmlElement* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
        const TiXmlElement* parent = j->FirstChildElement("parent");
        const TiXmlElement* child = j->FirstChildElement("child");
        const char* p = parent ? parent->Attribute("link") : nullptr;
        const char* c = child ? child->Attribute("link") : nullptr;
        const std::string name = j->Attribute("name") ? j->Attribute("name") : "";
        if (p && c && std::string(p) == c)
          throw InputError(
              SourceLocation{path, j->Row(), j->Column()}, "joint '" + name + "'",
              "its parent and child are the same link '" + std::string(p) + "'; expected a joint between two links");
        if (c && !child_of.emplace(c, name).second)
          throw InputError(SourceLocation{path, j->Row(), j->Column()}, "joint '" + name + "'",
                           "its child link '" + std::string(c) + "' is already the child of joint '" + child_of[c] +
                               "' (the joints form a cycle); expected the joints to form a tree");
      }
  }
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
  if (!model || !model->getRoot())
    throw InputError(SourceLocation{path, 0, 0}, "", "urdfdom cannot parse the file (its message is above)");
  t.name = options.name;
  if (t.name.empty()) {
    std::set<std::string> none;
    t.name = identifier(model->getName(), "imported", none);
  }
  std::string why;
  if (!is_valid_model_name(t.name, &why))
    throw InputError(SourceLocation{path, 0, 0}, "--name", quote(t.name) + ": " + why + "; choose one with --name");
  Gate gate(options, warn, t);
  const Locator locate(path, text);
  Walker w{t, options, warn, path, locate, gate, {}, {}, false, {}};
  w.symbols = {"t", "wx", "wy", "wz", "vx", "vy", "vz"};
  t.floating = options.floating;
  const urdf::LinkConstSharedPtr root = model->getRoot();
  if (t.floating) t.base_name = identifier(root->name, "base", w.labels);
  w.placed.insert(root.get());
  t.base_where = locate(root->name, {"link"});
  w.visit(root, t.floating ? -1 : -2, Frame{});
  // Links the walk from the root never reached hang from a cycle of joints apart from the tree.
  for (const auto& [name, link] : model->links_)
    if (!w.placed.count(link.get()))
      throw InputError(locate(name, {"link"}), "link '" + name + "'",
                       "is not reached from the root link '" + root->name +
                           "' (its joints form a cycle); expected the joints to form one tree");
  gate.finish();  // every element left out or refused, in one message
  if (t.bodies.empty())
    throw InputError(SourceLocation{path, 0, 0}, "", "the robot has no revolute, continuous or prismatic joints");
  return t;
}

}  // namespace hamel
