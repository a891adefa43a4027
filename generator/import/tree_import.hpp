// `hamel import`: robot description files (URDF through urdfdom, MJCF through MuJoCo's own compiler) turned
// into hamel kinematic-tree models (docs/import.md). Both readers fill the same numeric description of the
// tree, which tree_model_yaml writes as a model file (docs/model-format.md, "Kinematic trees").
#pragma once

#include "model/input_error.hpp"

#include <functional>
#include <set>
#include <string>
#include <vector>

namespace hamel {

/// A rigid transform: x ↦ R x + p.
struct Frame {
  double R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double p[3] = {0, 0, 0};
};

/// Mass properties accumulated in one body frame: mass, first moment and the inertia about the frame's
/// origin, so that bodies merged over fixed joints simply add up.
struct MassProperties {
  double mass = 0;
  double com[3] = {0, 0, 0};                                 ///< the centre of mass (0 while massless)
  double inertia[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};  ///< about the centre of mass
  /// Adds a body of mass m, centre of mass c and inertia I about c, all resolved in this frame. Held about the
  /// centre of mass and merged by the parallel-axis theorem between the two centres (I1 + I2 + m1 m2/(m1+m2) of the
  /// distance), a sum of positive semi-definite terms: about the frame's origin, the inertia of a heavy body far from
  /// it (mass 1e308) was the difference of two huge numbers and lost itself to cancellation, or overflowed.
  void add(double m, const double c[3], const double I[3][3]);
  /// The centre of mass and the inertia about it (zeros for a massless body).
  void about_com(double com[3], double inertia[3][3]) const;
};

struct ImportedBody {
  std::string name;
  int parent = -1;    ///< index of an earlier body; −1: the base (floating) or the world (fixed base)
  std::string joint;  ///< the joint coordinate's name
  bool prismatic = false;
  double axis[3] = {0, 0, 1};
  Frame joint_frame;  ///< the joint frame in the parent body's frame
  double armature = 0, damping = 0, stiffness = 0, reference = 0;
  MassProperties inertial;                             ///< in this body's frame
  std::vector<std::pair<std::string, double>> drives;  ///< generalized force Σ gain · input
  SourceLocation where;  ///< the joint's element in the robot file, for check_imported_tree's messages
  std::string what;      ///< "joint 'NAME'"
};

/// A closed loop (MJCF <equality> connect or weld): a point (and for a weld a frame) of body `body` held on one of
/// `to` (a body's name or "world"), each in its body's frame (the model key `loops`).
struct ImportedLoop {
  std::string name;
  bool weld = false;
  std::string body, to;
  double point[3] = {0, 0, 0}, to_point[3] = {0, 0, 0};
  double rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, to_rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};

struct ImportedTree {
  std::string source;  ///< the file as given
  std::string format;  ///< "MJCF (MuJoCo 2.2.2)" or "URDF (urdfdom)"
  std::string name;
  bool floating = false;
  std::string base_name;
  MassProperties base;               ///< floating base only
  std::vector<ImportedBody> bodies;  ///< parents before children
  double gravity[3] = {0, 0, 0};     ///< resolved in the world frame (fixed base: the base frame)
  Frame base_pose;                   ///< floating base: its frame in the world at the start (Γ(0) = Rᵀ g)
  std::vector<std::string> inputs;
  std::vector<ImportedLoop> loops;           ///< fixed base only
  std::vector<std::string> left_out;         ///< what --ignore dropped, for the description
  SourceLocation base_where, gravity_where;  ///< the base's and gravity's elements (line 0: the file)
};

struct ImportOptions {
  bool floating = false;         ///< URDF: the root link floats (SE3)
  std::string name;              ///< model name; default: from the file
  std::set<std::string> ignore;  ///< categories left out with a warning
};

/// The categories --ignore accepts.
const std::vector<std::string>& ignorable_categories();

using Warn = std::function<void(const std::string&)>;

/// MJCF through mj_loadXML; throws InputError naming the element the tree format cannot hold.
ImportedTree import_mjcf(const std::string& path, const ImportOptions& options, const Warn& warn);
/// URDF through urdfdom.
ImportedTree import_urdf(const std::string& path, const ImportOptions& options, const Warn& warn);

/// Checks the numbers an import read before they become a model: finite frames, axes, gains and gravity; mass
/// properties of a body (mass ≥ 0, inertia symmetric positive semi-definite with the triangle inequality);
/// damping, armature, stiffness ≥ 0; no moving joint that carries nothing (a singular mass matrix). Throws an
/// InputError naming the robot file's element (its joint, file:line), never one about the model it would write.
void check_imported_tree(const ImportedTree& tree);

/// The model file (YAML, schema 1) of an imported tree.
std::string tree_model_yaml(const ImportedTree& tree);

}  // namespace hamel
