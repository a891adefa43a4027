// generated/ is what the generator writes today: every package listed in generated/packages.txt is
// regenerated into a scratch folder with the real `hamel` binary and compared byte for byte (same files,
// same contents); folders under generated/ that the list does not name fail too. On failure, run
// tools/regenerate.sh and commit the result (generated/README.md).
#include "package_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace hamel::package_test {
namespace {

std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> names;
  if (!fs::is_directory(dir)) return names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) names.insert(fs::relative(e.path(), dir).string());
  return names;
}

TEST(GeneratedPackages, RegenerateByteIdentically) {
  const std::vector<ListedPackage> list = listed_packages();
  ASSERT_FALSE(list.empty());
  Scratch dir("regenerated");
  for (const ListedPackage& p : list) {
    SCOPED_TRACE("generated/" + p.folder + " from " + p.source + " " + p.flags);
    const fs::path fresh = dir.path() / p.folder, committed = source("generated/" + p.folder);
    const Outcome r = emit(source(p.source), p.flags, fresh);
    ASSERT_EQ(r.status, 0) << r.out;
    const std::set<std::string> names = files_in(fresh);
    EXPECT_FALSE(names.empty());
    EXPECT_EQ(files_in(committed), names) << "the files differ; run tools/regenerate.sh";
    for (const std::string& name : names)
      EXPECT_TRUE(slurp(fresh / name) == slurp(committed / name))
          << "generated/" << p.folder << "/" << name << " differs from a fresh emission; run tools/regenerate.sh";
  }
}

TEST(GeneratedPackages, EveryFolderIsListed) {
  const std::vector<ListedPackage> list = listed_packages();
  for (const auto& e : fs::directory_iterator(source("generated"))) {
    if (!e.is_directory()) continue;
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(std::any_of(list.begin(), list.end(), [&](const ListedPackage& p) { return p.folder == name; }))
        << "generated/" << name << " is not in generated/packages.txt";
  }
}

}  // namespace
}  // namespace hamel::package_test
