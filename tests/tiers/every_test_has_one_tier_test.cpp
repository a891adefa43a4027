// Every test ctest knows carries exactly one tier label: unit, reference or slow (tests/CMakeLists.txt, "Tiers").
// `tools/run-tests.sh --fast` runs the unit tier and CI's sanitizer stage selects by tier, so a test without a tier
// would silently drop out of one of them, and one with two would be counted twice.
//
// The list comes from `ctest --show-only=json-v1` over the whole build folder. That ctest runs in a scratch folder
// whose CTestTestfile.cmake only points at the build folder: ctest rewrites Testing/Temporary/LastTest.log in the
// folder it runs in, and the ctest that runs this test is writing the build folder's.
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::set<std::string> kTiers = {"unit", "reference", "slow"};

// What is wrong with the tiers of the tests in ctest's json-v1 listing, one line per finding (empty: nothing).
std::vector<std::string> tier_findings(const json& listing) {
  std::vector<std::string> findings;
  std::set<std::string> names;
  for (const json& test : listing.at("tests")) {
    const std::string name = test.at("name");
    if (!names.insert(name).second) findings.push_back(name + ": registered twice");
    std::vector<std::string> tiers;
    for (const json& property : test.value("properties", json::array()))
      if (property.at("name") == "LABELS")
        for (const json& label : property.at("value"))
          if (kTiers.count(label.get<std::string>())) tiers.push_back(label);
    if (tiers.size() != 1) {
      std::string found;
      for (const std::string& t : tiers) found += " " + t;
      findings.push_back(name + ": " + std::to_string(tiers.size()) + " tier labels" + found);
    }
  }
  return findings;
}

std::map<std::string, int> tests_per_tier(const json& listing) {
  std::map<std::string, int> count;
  for (const json& test : listing.at("tests"))
    for (const json& property : test.value("properties", json::array()))
      if (property.at("name") == "LABELS")
        for (const json& label : property.at("value"))
          if (kTiers.count(label.get<std::string>())) ++count[label.get<std::string>()];
  return count;
}

json build_listing() {
  const fs::path scratch = fs::path(HAMEL_TIERS_SCRATCH) / std::to_string(getpid());
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  std::ofstream(scratch / "CTestTestfile.cmake") << "subdirs([==[" << HAMEL_BUILD_DIR << "]==])\n";
  const hamel::test::Outcome listed =
      hamel::test::run("cd '" + scratch.string() + "' && '" + HAMEL_CTEST + "' --show-only=json-v1");
  fs::remove_all(scratch);
  EXPECT_EQ(listed.status, 0) << listed.out;
  return json::parse(listed.out);
}

TEST(TestTiers, EveryRegisteredTestHasExactlyOneTier) {
  const json listing = build_listing();
  // This test among them: the listing is the build's, not an empty one.
  bool self = false;
  for (const json& test : listing.at("tests"))
    self = self || test.at("name") == "TestTiers.EveryRegisteredTestHasExactlyOneTier";
  EXPECT_TRUE(self);
  EXPECT_GT(listing.at("tests").size(), 100u);
  for (const std::string& finding : tier_findings(listing)) ADD_FAILURE() << finding;
  const std::map<std::string, int> count = tests_per_tier(listing);
  // The tiers this build registers (HAMEL_TEST_TIERS, here joined by ',': "unit,reference" in CI's sanitizer stage)
  // have tests, the others none.
  const std::string built = "," + std::string(HAMEL_TEST_TIERS) + ",";
  for (const std::string& tier : kTiers) {
    const int n = count.count(tier) ? count.at(tier) : 0;
    if (built.find("," + tier + ",") != std::string::npos)
      EXPECT_GT(n, 0) << tier;
    else
      EXPECT_EQ(n, 0) << tier;
  }
}

// The check itself finds each kind of mistake (a listing written here, in ctest's json-v1 form).
TEST(TestTiers, TheCheckFindsTestsWithoutOrWithTwoTiers) {
  const json listing = json::parse(R"({"kind": "ctestInfo", "tests": [
    {"name": "A.Unlabelled", "properties": [{"name": "WORKING_DIRECTORY", "value": "/tmp"}]},
    {"name": "B.NoProperties"},
    {"name": "C.TopicOnly", "properties": [{"name": "LABELS", "value": ["phase"]}]},
    {"name": "D.TwoTiers", "properties": [{"name": "LABELS", "value": ["unit", "slow"]}]},
    {"name": "E.Fine", "properties": [{"name": "LABELS", "value": ["reference", "phase"]}]},
    {"name": "E.Fine", "properties": [{"name": "LABELS", "value": ["reference"]}]}]})");
  const std::vector<std::string> want = {"A.Unlabelled: 0 tier labels", "B.NoProperties: 0 tier labels",
                                         "C.TopicOnly: 0 tier labels", "D.TwoTiers: 2 tier labels unit slow",
                                         "E.Fine: registered twice"};
  EXPECT_EQ(tier_findings(listing), want);
}

}  // namespace
