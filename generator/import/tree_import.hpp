// `hamel import`: robot description files (URDF through urdfdom, MJCF through MuJoCo's own compiler) turned
// into hamel kinematic-tree models (docs/import.md). Both readers fill the same numeric description of the
// tree, which tree_model_yaml writes as a model file (docs/model-format.md, "Kinematic trees").
#pragma once

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
  double moment[3] = {0, 0, 0};  ///< m c
  double origin_inertia[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  /// Adds a body of mass m, centre of mass c and inertia I about c, all resolved in this frame.
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
  std::vector<std::string> left_out;  ///< what --ignore dropped, for the description
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

/// The model file (YAML, schema 1) of an imported tree.
std::string tree_model_yaml(const ImportedTree& tree);

}  // namespace hamel
