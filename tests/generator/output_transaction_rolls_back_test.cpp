// A run's outputs are committed together (report/atomic_file.hpp, OutputTransaction): when the rename of one of
// several outputs into place fails, the outputs renamed before it get their old content back (or are removed where
// there was none), so no run leaves some outputs new and others old. The failure is made here by turning the second
// output's target into a non-empty folder between opening and committing (rename(2) cannot replace that).
#include "report/atomic_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

class Rollback : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(testing::TempDir()) /
          (std::string("rollback_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  // Nothing but `names` in the folder: no temporary or set-aside file is left behind.
  void expect_only(const std::set<std::string>& names) {
    std::set<std::string> found;
    for (const auto& e : fs::directory_iterator(dir)) found.insert(e.path().filename().string());
    EXPECT_EQ(found, names);
  }
  fs::path dir;
};

TEST_F(Rollback, AFailedSecondRenameRestoresTheFirstOutput) {
  spit(dir / "a.csv", "old a\n");
  spit(dir / "b.svg", "old b\n");
  spit(dir / "c.txt", "old c\n");
  std::string message;
  {
    hamel::OutputTransaction out;
    out.open((dir / "a.csv").string(), "--out") << "new a\n";
    out.open((dir / "b.svg").string(), "--plot") << "new b\n";
    out.open((dir / "c.txt").string(), "--other") << "new c\n";
    fs::remove(dir / "b.svg");
    fs::create_directory(dir / "b.svg");
    spit(dir / "b.svg" / "inside", "kept\n");
    try {
      out.commit();
    } catch (const hamel::OutputError& e) {
      message = e.what();
    }
  }  // the transaction ends as a failed run's does: its temporaries go
  EXPECT_NE(message.find("b.svg"), std::string::npos) << message;
  EXPECT_NE(message.find("the other files keep their old content"), std::string::npos) << message;
  EXPECT_EQ(slurp(dir / "a.csv"), "old a\n");
  EXPECT_EQ(slurp(dir / "c.txt"), "old c\n");
  EXPECT_EQ(slurp(dir / "b.svg" / "inside"), "kept\n");
  expect_only({"a.csv", "b.svg", "c.txt"});
}

TEST_F(Rollback, AnOutputThatDidNotExistIsRemovedAgain) {
  spit(dir / "b.svg", "old b\n");
  {
    hamel::OutputTransaction out;
    out.open((dir / "a.csv").string(), "--out") << "new a\n";  // no old file
    out.open((dir / "b.svg").string(), "--plot") << "new b\n";
    fs::remove(dir / "b.svg");
    fs::create_directory(dir / "b.svg");
    spit(dir / "b.svg" / "inside", "kept\n");
    EXPECT_THROW(out.commit(), hamel::OutputError);
  }
  EXPECT_FALSE(fs::exists(dir / "a.csv"));
  expect_only({"b.svg"});
}

TEST_F(Rollback, ASuccessfulCommitLeavesNothingAside) {
  spit(dir / "a.csv", "old a\n");
  {
    hamel::OutputTransaction out;
    out.open((dir / "a.csv").string(), "--out") << "new a\n";
    out.open((dir / "b.svg").string(), "--plot") << "new b\n";
    out.commit();
  }
  EXPECT_EQ(slurp(dir / "a.csv"), "new a\n");
  EXPECT_EQ(slurp(dir / "b.svg"), "new b\n");
  expect_only({"a.csv", "b.svg"});
}

}  // namespace
