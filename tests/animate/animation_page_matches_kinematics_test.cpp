// The page `hamel animate` writes, loaded in a real headless browser (Debian's chromium, --dump-dom): it loads
// without script errors, and at two times of the trajectory three.js's scene graph holds every body's mesh at the
// body's centre of mass and its box along the body's principal axes as computed here, without the page and without
// hamel's numeric/body_poses: the joint angles and the base's pose from the CSV of a separate `hamel simulate` or
// `hamel phase` run, the bodies placed by an Eigen forward kinematics over the model file's joints, and for MuJoCo's
// humanoid also by MuJoCo itself (mj_kinematics, xipos). Cases: the four-bar as a tree (fixed base, closed loop), the
// satellite's phase experiment (paper Sec. 6c, as a tree on SE(3)) and the imported humanoid falling under gravity
// (SE(3) base, 21 hinges).
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using hamel::test::run;
using hamel::test::source;
using Vec = Eigen::Vector3d;
using Mat = Eigen::Matrix3d;

const std::string hamel_bin = HAMEL_BINARY;

std::string browser() {
  for (const char* name : {"chromium-headless-shell", "chromium", "chromium-browser"})
    if (run(std::string("command -v ") + name + " >/dev/null 2>&1").status == 0) return name;
  return "";
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hamel_animate_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A CSV as columns by name.
struct Table {
  std::map<std::string, std::vector<double>> column;
  std::size_t rows = 0;
};

Table read_csv(const fs::path& path) {
  std::istringstream in(hamel::test::slurp(path));
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::istringstream header(line); std::getline(header, cell, ',');) names.push_back(cell);
  Table t;
  while (std::getline(in, line)) {
    std::istringstream cells(line);
    for (std::size_t k = 0; std::getline(cells, cell, ','); ++k) t.column[names.at(k)].push_back(std::stod(cell));
    ++t.rows;
  }
  return t;
}

// What the page wrote into <pre id="probe"> and <pre id="errors"> when opened at #t=<t>.
struct Probe {
  bool answered = false;
  double t = 0;
  std::map<std::string, Vec> position;
  std::map<std::string, Eigen::Quaterniond> orientation;
  std::string errors, dom;
};

std::string element_text(const std::string& dom, const std::string& id) {
  const std::string open = "<pre id=\"" + id + "\">";
  const std::size_t a = dom.find(open);
  if (a == std::string::npos) return "";
  const std::size_t b = dom.find("</pre>", a);
  return dom.substr(a + open.size(), b - a - open.size());
}

Probe probe(const fs::path& page, double t) {
  char when[40];
  std::snprintf(when, sizeof when, "%.17g", t);
  const fs::path profile = page.parent_path() / "chromium-profile";
  const std::string command = browser() +
                              " --headless --no-sandbox --disable-gpu --use-gl=swiftshader --enable-unsafe-swiftshader "
                              "--no-first-run --user-data-dir=" +
                              profile.string() + " --dump-dom 'file://" + fs::absolute(page).string() + "#t=" + when +
                              "' 2>/dev/null";
  Probe p;
  p.dom = run(command).out;
  p.errors = element_text(p.dom, "errors");
  const std::string text = element_text(p.dom, "probe");
  if (text.empty()) return p;
  const nlohmann::json j = nlohmann::json::parse(text);
  p.answered = true;
  p.t = j.at("t").get<double>();
  for (const auto& [name, v] : j.at("positions").items()) p.position[name] = Vec(v[0], v[1], v[2]);
  for (const auto& [name, v] : j.at("orientations").items())
    p.orientation[name] = Eigen::Quaterniond(v[3].get<double>(), v[0], v[1], v[2]);
  return p;
}

double number(const GiNaC::ex& e, const GiNaC::exmap& at) {
  return GiNaC::ex_to<GiNaC::numeric>(e.subs(at).evalf()).to_double();
}

// Every tree body's centre of mass in the world (base first), by g_i = g_parent (rotation, offset) exp(q_i S_i),
// written here with Eigen from the model file's joints: the page's poses come from numeric/body_poses.cpp.
// With `inertia`, also each body's inertia about its centre of mass in world axes, R Θ Rᵀ.
std::map<std::string, Vec> centres_of_mass(const hamel::Model& model, const std::vector<double>& q, const Mat& R0,
                                           const Vec& p0, std::map<std::string, Mat>* inertia = nullptr) {
  const hamel::KinematicTree& tree = model.tree          ? *model.tree
                                     : model.closed_tree ? *model.closed_tree
                                                         : *model.bundle->tree;
  GiNaC::exmap at;
  for (const auto& p : model.parameters) at[p.symbol] = p.default_value;
  const auto vec = [&](const GiNaC::ex(&e)[3]) { return Vec(number(e[0], at), number(e[1], at), number(e[2], at)); };
  std::vector<Mat> R{R0};
  std::vector<Vec> p{p0};
  std::map<std::string, Vec> com;
  const auto theta = [&](const hamel::RigidBody& b, const Mat& R) {
    Mat I;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) I(i, j) = number(b.inertia[i][j], at);
    if (inertia) (*inertia)[b.name] = R * I * R.transpose();
  };
  if (number(tree.base.mass, at) > 0) {
    com[tree.base.name] = p0 + R0 * vec(tree.base.com);
    theta(tree.base, R0);
  }
  for (std::size_t k = 0; k < tree.bodies.size(); ++k) {
    const hamel::TreeBody& b = tree.bodies[k];
    Mat link;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) link(i, j) = number(b.rotation[i][j], at);
    const Vec axis = vec(b.axis).normalized();
    const Mat& Rp = R[static_cast<std::size_t>(b.parent + 1)];
    const Vec& pp = p[static_cast<std::size_t>(b.parent + 1)];
    const Mat Rj = Rp * link * (b.prismatic ? Mat::Identity() : Mat(Eigen::AngleAxisd(q[k], axis)));
    const Vec pj = pp + Rp * vec(b.offset) + (b.prismatic ? Vec(Rp * link * axis * q[k]) : Vec::Zero());
    R.push_back(Rj);
    p.push_back(pj);
    if (number(b.body.mass, at) > 0) {
      com[b.body.name] = pj + Rj * vec(b.body.com);
      theta(b.body, Rj);
    }
  }
  return com;
}

// The row of `table` nearest to time t.
std::size_t row_at(const Table& table, double t) {
  const std::vector<double>& ts = table.column.at("t");
  std::size_t best = 0;
  for (std::size_t k = 1; k < ts.size(); ++k)
    if (std::abs(ts[k] - t) < std::abs(ts[best] - t)) best = k;
  return best;
}

Mat base_rotation(const Table& table, std::size_t row) {
  Mat R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = table.column.at("R" + std::to_string(i) + std::to_string(j))[row];
  return R;
}

Vec base_position(const Table& table, std::size_t row) {
  return Vec(table.column.at("px")[row], table.column.at("py")[row], table.column.at("pz")[row]);
}

// The page at time t against `expected` (every drawn body, named): loaded without errors, each mesh within tol.
// With `inertia` (world axes), also each box's orientation: its axes are the principal axes, smallest moment first, so
// R_box diag(λ₁ ≤ λ₂ ≤ λ₃) R_boxᵀ is the body's inertia in world axes, whichever axes a repeated moment leaves free.
void expect_page_matches(const fs::path& page, double t, const std::map<std::string, Vec>& expected, double tol,
                         const std::map<std::string, Mat>* inertia = nullptr) {
  const Probe p = probe(page, t);
  ASSERT_TRUE(p.answered) << "the page did not answer the probe at t = " << t << "; the browser's DOM:\n"
                          << p.dom.substr(0, 2000);
  EXPECT_EQ(p.errors, "") << "script errors at t = " << t;
  EXPECT_NEAR(p.t, t, 1e-12);
  std::size_t bodies = 0;
  for (const auto& [name, where] : p.position) {
    if (name.find(" frame") != std::string::npos) continue;  // the group frame's axes: checked by the callers
    ++bodies;
    const auto it = expected.find(name);
    ASSERT_NE(it, expected.end()) << "the page draws '" << name << "', which has no centre of mass here";
    EXPECT_LT((where - it->second).norm(), tol)
        << name << " at t = " << t << ": page " << where.transpose() << ", expected " << it->second.transpose();
    if (inertia) {
      const Mat& I = inertia->at(name);
      const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Mat>(I).eigenvalues();
      const Mat R = p.orientation.at(name).normalized().toRotationMatrix();
      EXPECT_LT((R * moments.asDiagonal() * R.transpose() - I).norm(), 1e-9 * moments.maxCoeff())
          << name << "'s box is turned away from its principal axes at t = " << t;
    }
  }
  EXPECT_EQ(bodies, expected.size()) << "bodies drawn at t = " << t;
}

class AnimationPage : public ::testing::Test {
 protected:
  void SetUp() override {
    if (browser().empty())
      GTEST_SKIP() << "neither chromium-headless-shell nor chromium is installed (Debian package "
                      "chromium-headless-shell, installed by tools/install-deps.sh): the page cannot be loaded in a "
                      "browser here";
  }
};

TEST_F(AnimationPage, FourBarTreeBodiesFollowTheSimulatedJoints) {
  const fs::path dir = scratch("four_bar");
  const std::string model = source("models/four_bar_tree.yaml");
  const std::string options = " --t-end 1 --sample 0.01";
  ASSERT_EQ(run(hamel_bin + " animate " + model + options + " -o " + (dir / "page.html").string() + " 2>&1").status, 0);
  ASSERT_EQ(run(hamel_bin + " simulate " + model + options + " --out " + (dir / "run.csv").string() + " 2>&1").status,
            0);
  const Table csv = read_csv(dir / "run.csv");
  const hamel::Model m = hamel::load_model(model);
  for (double t : {0.25, 0.73}) {
    const std::size_t row = row_at(csv, t);
    std::vector<double> q;
    for (const auto& c : m.coordinates) q.push_back(csv.column.at(c.get_name())[row]);
    std::map<std::string, Mat> inertia;
    const std::map<std::string, Vec> com = centres_of_mass(m, q, Mat::Identity(), Vec::Zero(), &inertia);
    expect_page_matches(dir / "page.html", csv.column.at("t")[row], com, 1e-9, &inertia);
  }
  fs::remove_all(dir);
}

// The same four-bar in general coordinates with `bodies:` (each pose written as an expression): the rods' centres from
// the model's description, the absolute angles theta_k of rods hinged at the origin, the crank's tip and (d, 0).
TEST_F(AnimationPage, FourBarBodiesFollowTheirWrittenPoses) {
  const fs::path dir = scratch("four_bar_bodies");
  const std::string model = source("models/four_bar.yaml");
  const std::string options = " --t-end 1 --sample 0.01";
  ASSERT_EQ(run(hamel_bin + " animate " + model + options + " -o " + (dir / "page.html").string() + " 2>&1").status, 0);
  ASSERT_EQ(run(hamel_bin + " simulate " + model + options + " --out " + (dir / "run.csv").string() + " 2>&1").status,
            0);
  const Table csv = read_csv(dir / "run.csv");
  const double l1 = 0.2, l2 = 0.6, l3 = 0.45, d = 0.5;  // models/four_bar.yaml's parameters
  for (double t : {0.31, 0.88}) {
    const std::size_t row = row_at(csv, t);
    const double a = csv.column.at("theta1")[row], b = csv.column.at("theta2")[row], c = csv.column.at("theta3")[row];
    const Vec tip(l1 * std::cos(a), l1 * std::sin(a), 0);
    const std::map<std::string, Vec> com = {{"crank", tip / 2},
                                            {"coupler", tip + l2 / 2 * Vec(std::cos(b), std::sin(b), 0)},
                                            {"rocker", Vec(d, 0, 0) + l3 / 2 * Vec(std::cos(c), std::sin(c), 0)}};
    expect_page_matches(dir / "page.html", csv.column.at("t")[row], com, 1e-9);
  }
  fs::remove_all(dir);
}

TEST_F(AnimationPage, SatellitePhaseExperimentBodiesFollowTheBase) {
  const fs::path dir = scratch("satellite");
  const std::string model = source("models/satellite_se3_tree.yaml");
  const std::string path = "pi*(cos(2*pi*t) - 1); pi*sin(2*pi*t); pi/2*sin(4*pi*t)";
  const std::string options = " --path \"" + path + "\" --period 1 --cycles 2";
  ASSERT_EQ(run(hamel_bin + " animate " + model + options + " -o " + (dir / "page.html").string() + " 2>&1").status, 0);
  ASSERT_EQ(run(hamel_bin + " phase " + model + options + " --out " + dir.string() + " 2>&1").status, 0);
  const Table csv = read_csv(dir / "satellite_se3_tree_phase.csv");
  const hamel::Model m = hamel::load_model(model);
  for (double t : {0.37, 1.61}) {
    const std::size_t row = row_at(csv, t);
    const double s = csv.column.at("t")[row];
    const std::vector<double> r = {M_PI * (std::cos(2 * M_PI * s) - 1), M_PI * std::sin(2 * M_PI * s),
                                   M_PI / 2 * std::sin(4 * M_PI * s)};
    const Mat R = base_rotation(csv, row);
    const Vec p = base_position(csv, row);
    std::map<std::string, Mat> inertia;
    const std::map<std::string, Vec> com = centres_of_mass(m, r, R, p, &inertia);
    expect_page_matches(dir / "page.html", s, com, 1e-9, &inertia);
    const Probe frame = probe(dir / "page.html", s);
    ASSERT_EQ(frame.position.count("SE3 frame"), 1u);
    EXPECT_LT((frame.position.at("SE3 frame") - p).norm(), 1e-12) << "the group frame's origin at t = " << s;
  }
  fs::remove_all(dir);
}

TEST_F(AnimationPage, ImportedHumanoidMatchesMujocoKinematics) {
  const fs::path dir = scratch("humanoid");
  const std::string yaml = (dir / "humanoid.yaml").string();
  ASSERT_EQ(run(hamel_bin + " import " HAMEL_HUMANOID_XML " -o " + yaml + " --ignore contacts,limits 2>&1").status, 0);
  // Joints and base turning from the start, so that every joint's angle and the base's rotation are tested.
  const std::string options =
      " --integrator rkmk4 --t-end 0.3 --sample 0.01 --init wx=0.5,wy=-0.3,abdomen_z_dot=1,right_shoulder1_dot=3,"
      "left_elbow_dot=-2,right_hip_x_dot=1.5,left_knee_dot=-4,right_ankle_y_dot=2";
  ASSERT_EQ(run(hamel_bin + " animate " + yaml + options + " -o " + (dir / "page.html").string() + " 2>&1").status, 0);
  ASSERT_EQ(run(hamel_bin + " simulate " + yaml + options + " --out " + (dir / "run.csv").string() + " 2>&1").status,
            0);
  const Table csv = read_csv(dir / "run.csv");
  const hamel::Model m = hamel::load_model(yaml);

  char err[1000] = "";
  mjModel* mj = mj_loadXML(HAMEL_HUMANOID_XML, nullptr, err, sizeof err);
  ASSERT_NE(mj, nullptr) << err;
  mjData* d = mj_makeData(mj);
  std::map<std::string, double> mass;
  {
    GiNaC::exmap at;
    for (const auto& p : m.parameters) at[p.symbol] = p.default_value;
    const hamel::KinematicTree& tree = *m.bundle->tree;
    mass[tree.base.name] = number(tree.base.mass, at);
    for (const hamel::TreeBody& b : tree.bodies) mass[b.body.name] = number(b.body.mass, at);
  }
  for (double t : {0.1, 0.29}) {
    const std::size_t row = row_at(csv, t);
    std::vector<double> q;
    for (const auto& c : m.coordinates) q.push_back(csv.column.at(c.get_name())[row]);
    const Mat R = base_rotation(csv, row);
    const Vec p = base_position(csv, row);
    std::map<std::string, Mat> inertia;
    const std::map<std::string, Vec> com = centres_of_mass(m, q, R, p, &inertia);
    expect_page_matches(dir / "page.html", csv.column.at("t")[row], com, 1e-9, &inertia);

    // MuJoCo's own forward kinematics at the same state: free joint (p, quaternion of R), hinges by name.
    mj_resetData(mj, d);
    const Eigen::Quaterniond quat(R);
    const double qpos0[7] = {p.x(), p.y(), p.z(), quat.w(), quat.x(), quat.y(), quat.z()};
    std::copy(qpos0, qpos0 + 7, d->qpos);
    for (std::size_t k = 0; k < m.coordinates.size(); ++k) {
      const int j = mj_name2id(mj, mjOBJ_JOINT, m.coordinates[k].get_name().c_str());
      ASSERT_GE(j, 0) << m.coordinates[k].get_name();
      d->qpos[mj->jnt_qposadr[j]] = q[k];
    }
    mj_kinematics(mj, d);
    const Probe page = probe(dir / "page.html", csv.column.at("t")[row]);
    int matched = 0;
    for (const auto& [name, where] : page.position) {
      // A MuJoCo body without joints is merged into its parent on import (docs/import.md), which moves the parent's
      // centre of mass: compared are the bodies whose mass is MuJoCo's own.
      const int b = mj_name2id(mj, mjOBJ_BODY, name.c_str());
      if (b < 0 || std::abs(mass.at(name) - mj->body_mass[b]) > 1e-12 * mj->body_mass[b]) continue;
      ++matched;
      const Vec xipos(d->xipos[3 * b], d->xipos[3 * b + 1], d->xipos[3 * b + 2]);
      EXPECT_LT((where - xipos).norm(), 1e-9) << name << " at t = " << t << " against MuJoCo's xipos";
    }
    EXPECT_GE(matched, 10) << "bodies of the page that MuJoCo's humanoid names";
  }
  mj_deleteData(d);
  mj_deleteModel(mj);
  fs::remove_all(dir);
}

}  // namespace

namespace {

// What `hamel animate` refuses, with exit status 2 and nothing written (no browser needed).
TEST(AnimateCli, RefusesBadInputAndWritesNothing) {
  const fs::path dir = scratch("cli");
  const std::string page = (dir / "page.html").string();
  const auto animate = [&](const std::string& args) {
    return run(hamel_bin + " animate " + args + " -o " + page + " 2>&1");
  };
  // A Lagrangian says nothing of where the bodies are.
  const hamel::test::Outcome lagrangian = animate(source("models/double_pendulum.yaml") + " --t-end 1");
  EXPECT_EQ(lagrangian.status, 2) << lagrangian.out;
  EXPECT_NE(lagrangian.out.find("double_pendulum.yaml"), std::string::npos) << lagrangian.out;
  EXPECT_NE(lagrangian.out.find("'bodies'"), std::string::npos) << lagrangian.out;
  // A phase experiment and simulate's options together.
  const hamel::test::Outcome both = animate(source("models/satellite_se3_tree.yaml") + " --path \"t; t; t\" --t-end 1");
  EXPECT_EQ(both.status, 2) << both.out;
  EXPECT_NE(both.out.find("--path"), std::string::npos) << both.out;
  // Bundle models need the group element: rkmk4 only.
  const hamel::test::Outcome integrator =
      animate(source("models/satellite_se3_tree.yaml") + " --t-end 1 --integrator dopri5");
  EXPECT_EQ(integrator.status, 2) << integrator.out;
  EXPECT_NE(integrator.out.find("rkmk4"), std::string::npos) << integrator.out;
  const hamel::test::Outcome up = animate(source("models/four_bar_tree.yaml") + " --t-end 1 --up 0,0");
  EXPECT_EQ(up.status, 2) << up.out;
  EXPECT_NE(up.out.find("--up"), std::string::npos) << up.out;
  EXPECT_FALSE(fs::exists(page));
  EXPECT_TRUE(fs::is_empty(dir)) << "temporary files left behind";
  const hamel::test::Outcome help = run(hamel_bin + " animate --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--path"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
