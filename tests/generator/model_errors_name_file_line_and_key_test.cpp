// Malformed model files give InputError messages naming file:line:column, the key and what was
// expected. (The CLI turns these into exit status 2; see cli_contract_test.)
#include "derive/derivation.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

namespace {

const std::string good_header =
    "name: sleigh\n"
    "parameters: {m: 1, a: 0.2}\n"
    "coordinates: [x, y, theta]\n";
const std::string good_velocities =
    "quasi_velocities:\n"
    "  names: [u_lat, v, omega]\n"
    "  A:\n"
    "    - [\"-sin(theta)\", \"cos(theta)\", 0]\n"
    "    - [\"cos(theta)\", \"sin(theta)\", 0]\n"
    "    - [0, 0, 1]\n";
const std::string good_lagrangian = "lagrangian: \"m/2*(x_dot^2 + y_dot^2) + m*a^2/2*theta_dot^2\"\n";

struct BadCase {
  std::string label, text, expected_location, expected_fragment;
};

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.label; }

class BadModel : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadModel, ErrorNamesLocationAndProblem) {
  const BadCase& c = GetParam();
  try {
    const hamel::Model model = hamel::load_model_from_text(c.text, "bad.yaml");
    (void)hamel::derive(model);
    FAIL() << "no error for " << c.label;
  } catch (const hamel::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(c.expected_location), std::string::npos) << message;
    EXPECT_NE(message.find(c.expected_fragment), std::string::npos) << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, BadModel,
    ::testing::Values(
        BadCase{"yaml_syntax", "name: [unclosed\n", "bad.yaml:", "YAML syntax error"},
        BadCase{"unknown_key_did_you_mean", good_header + good_velocities + good_lagrangian + "constraint: [u_lat]\n",
                "bad.yaml:11:1", "did you mean 'constraints'"},
        BadCase{"missing_lagrangian", good_header + good_velocities, "bad.yaml:1:1",
                "'lagrangian': missing required key"},
        BadCase{"unknown_symbol", good_header + good_velocities + "lagrangian: \"m*x_dot^2 + k\"\n", "bad.yaml:10:13",
                "unknown name 'k'"},
        BadCase{"parse_error", good_header + good_velocities + "lagrangian: \"m*(x_dot^2\"\n", "bad.yaml:10:13",
                "cannot parse expression"},
        BadCase{"keyword_name", "name: sleigh\ncoordinates: [x, double]\n", "bad.yaml:2:18", "C++ keyword"},
        BadCase{"dot_suffix", "name: s\ncoordinates: [x_dot]\n", "bad.yaml:2:15", "ends in '_dot'"},
        BadCase{"clash", "name: s\nparameters: {x: 1}\ncoordinates: [x]\n", "bad.yaml:3:15", "already declared"},
        BadCase{"wrong_row_count", good_header + "quasi_velocities:\n  names: [a1, a2, a3]\n  A: [[1, 0, 0]]\n",
                "bad.yaml:6:6", "expected a list of 3 rows"},
        BadCase{"singular_A",
                good_header +
                    "quasi_velocities:\n  names: [a1, a2, a3]\n  A: [[1, 0, \"cos(theta)\"], [0, 1, 0], "
                    "[\"sin(theta)^2+cos(theta)^2\", 0, \"cos(theta)\"]]\n" +
                    good_lagrangian,
                "bad.yaml:6:6", "singular"},
        BadCase{"wrong_B", good_header + good_velocities + "  B: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n" + good_lagrangian,
                "bad.yaml:10:6", "B is not the inverse of A"},
        BadCase{"unknown_constraint", good_header + good_velocities + good_lagrangian + "constraints: [u_lt]\n",
                "bad.yaml:11:15", "did you mean 'u_lat'"},
        BadCase{"non_finite_parameter", "name: s\nparameters: {m: .inf}\ncoordinates: [x]\n", "bad.yaml:2:17",
                "finite number"},
        BadCase{"time_in_A",
                good_header + "quasi_velocities:\n  names: [a1, a2, a3]\n  A: [[t, 0, 0], [0, 1, 0], [0, 0, 1]]\n",
                "bad.yaml:6:8", "coordinates and parameters only"},
        BadCase{"core_key_in_bundle_model", good_header + "group: SO3\n", "bad.yaml:3:1",
                "does not belong in a bundle model"},
        BadCase{"bundle_key_in_core_model", good_header + good_velocities + good_lagrangian + "shape: [r]\n",
                "bad.yaml:11:1", "is a principal-bundle key"},
        BadCase{"unknown_group", "name: b\ngroup: SO4\ngroup_velocity: [w1, w2, w3]\nkinetic: \"w1^2\"\n",
                "bad.yaml:2:8", "unknown group 'SO4'"},
        BadCase{"bad_trivialization",
                "name: b\ngroup: SO3\ntrivialization: middle\ngroup_velocity: [w1, w2, w3]\nkinetic: \"w1^2\"\n",
                "bad.yaml:3:17", "expected 'left'"},
        BadCase{"group_velocity_count", "name: b\ngroup: SE3\ngroup_velocity: [w1, w2, w3]\nkinetic: \"w1^2\"\n",
                "bad.yaml:3:17", "expected 6 names"},
        BadCase{"singular_locked_inertia",
                "name: b\ngroup: SO3\ngroup_velocity: [w1, w2, w3]\nshape: [r]\nkinetic: \"w1^2 + r_dot^2\"\n",
                "bad.yaml:5:10", "locked inertia"},
        // A model with `bodies` has no `kinetic`: the error names the key it has (issue 49).
        BadCase{"singular_locked_inertia_of_bodies",
                "name: b\ngroup: SO3\ngroup_velocity: [w1, w2, w3]\nshape: [r]\nbodies:\n"
                "  - {name: rod, mass: 1, com: [0, 0, 0], inertia: [[0, 0, 0], [0, 1, 0], [0, 0, 1]],\n"
                "     twist: [w1, w2, \"w3 + r_dot\", 0, 0, 0]}\n",
                "bad.yaml:6:3", "'bodies': the locked inertia"},
        BadCase{"kinematic_connection_shape",
                "name: b\ngroup: SE2\ngroup_velocity: [w, vx, vy]\nshape: [r]\n"
                "connection: {kinematic: [[1], [0]]}\nkinetic: \"r_dot^2\"\n",
                "bad.yaml:5:25", "expected 3 rows"}),
    [](const ::testing::TestParamInfo<BadCase>& info) { return info.param.label; });

// Extreme scales: A = [[1e200]] and A = diag(1e200, 1e-200) (det exactly 1) are regular. Their regularity was
// decided in doubles, where the product of the row lengths overflows (and 0 * inf is NaN), so both were refused
// as "singular at every sampled configuration ... is -nan". Decided in rationals now, they derive, with the exact B.
TEST(RegularA, ExtremeScalesAreNotSingular) {
  const std::string one =
      "name: s\ncoordinates: [x]\nquasi_velocities:\n  names: [v]\n  A: [[\"1e200\"]]\n"
      "lagrangian: \"1/2*x_dot^2 - x^2/2\"\n";
  const hamel::Derivation d1 = hamel::derive(hamel::load_model_from_text(one, "one.yaml"));
  ASSERT_EQ(d1.quasi_velocities.B.rows(), 1u);
  EXPECT_EQ(d1.quasi_velocities.B(0, 0), GiNaC::pow(GiNaC::numeric(10), -200));

  const std::string diagonal =
      "name: s\ncoordinates: [x, y]\nquasi_velocities:\n  names: [u, w]\n"
      "  A: [[\"1e200\", 0], [0, \"1e-200\"]]\nlagrangian: \"1/2*x_dot^2 + 1/2*y_dot^2 - x^2/2\"\n";
  const hamel::Derivation d2 = hamel::derive(hamel::load_model_from_text(diagonal, "diagonal.yaml"));
  ASSERT_EQ(d2.quasi_velocities.B.rows(), 2u);
  EXPECT_EQ(d2.quasi_velocities.B(0, 0), GiNaC::pow(GiNaC::numeric(10), -200));
  EXPECT_EQ(d2.quasi_velocities.B(1, 1), GiNaC::pow(GiNaC::numeric(10), 200));
  EXPECT_EQ(d2.quasi_velocities.B(0, 1), GiNaC::ex(0));
  EXPECT_EQ(d2.quasi_velocities.B(1, 0), GiNaC::ex(0));
}

}  // namespace
