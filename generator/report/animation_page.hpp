// One self-contained HTML page that plays a motion in 3-D with three.js (Debian libjs-three, r111, inlined: the page
// needs no network): boxes posed over time, the base's path as a line, play/pause, a time slider and orbit controls.
// `hamel animate` fills it from a simulation or a phase experiment (docs/animate.md).
//
// The page also answers a probe, for tests and scripts: opened with a fragment `#t=<time>` it stops at that time and
// writes, into <pre id="probe">, the world position of every drawn body's mesh read back from three.js's scene graph
// ({"t": ..., "positions": {"<body>": [x, y, z], ...}, "orientations": {"<body>": [x, y, z, w], ...}}: the box's axes
// are the principal axes of the body's inertia, smallest moment first), whether or not WebGL draws; errors are in
// <pre id="errors">.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace hamel {

struct AnimationBody {
  std::string name;
  std::array<double, 3> edges{0, 0, 0};  ///< the box's edge lengths along its own axes
};

/// A box's placement in the world: position of its centre, orientation as a unit quaternion (x, y, z, w).
using BoxPose = std::array<double, 7>;

struct Animation {
  std::string title;
  std::array<double, 3> up{0, 0, 1};  ///< the world direction drawn upward
  std::vector<AnimationBody> bodies;
  std::vector<double> times;                ///< increasing
  std::vector<std::vector<BoxPose>> poses;  ///< per time, per body
  /// The group frame (floating base) per time, drawn as axes with its origin's path as a line; empty: none.
  std::vector<BoxPose> base;
  std::string base_name = "group frame";
  std::vector<std::string> notes;  ///< shown under the title
};

/// The unit quaternion (x, y, z, w) of a rotation matrix (row-major).
std::array<double, 4> quaternion_of(const std::array<double, 9>& R);

/// Whether this build carries three.js (it did not find libjs-three when configured otherwise).
bool animation_pages_available();

/// Why a build without three.js writes no page, and what to do.
const char* missing_three_js();

/// The page's HTML; throws std::runtime_error (missing_three_js()) when the build has no three.js.
std::string render_animation_page(const Animation& animation);

}  // namespace hamel
