// Outputs are never lost or replaced by something else: special files are written through, not replaced;
// emit owns a folder only through the manifest it wrote; the swap is one atomic exchange; SIGINT/SIGTERM
// remove temporaries (exit 130/143) and a later run sweeps those of a killed one; failed writes, stdout
// included, exit 1.
#include "run_hamel.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <thread>
#include <vector>

extern char** environ;

namespace {

using namespace hamel_test;

const char* spring =
    "name: spring\n"
    "parameters: {m: 1, k: 4}\n"
    "coordinates: [x]\n"
    "quasi_velocities: {names: [u], A: [[1]]}\n"
    "lagrangian: \"m/2*x_dot^2 - k/2*x^2\"\n";

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

bool has_temporaries(const fs::path& dir) {
  for (const std::string& n : names_in(dir))
    if (n.find(".tmp-") != std::string::npos || n.find(".old-") != std::string::npos) return true;
  return false;
}

// hamel started directly (no shell between), stdout and stderr to files, so that signals reach it.
pid_t start_hamel(const std::vector<std::string>& args, const fs::path& out, const fs::path& err) {
  std::vector<std::string> all{hamel_binary()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

int wait_status(pid_t pid) {
  int raw = 0;
  waitpid(pid, &raw, 0);
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -WTERMSIG(raw);
}

class Output : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = scratch_dir(std::string("out_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    spit(dir / "spring.yaml", spring);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return shell_quote((dir / name).string()); }
  fs::path dir;
};

TEST_F(Output, SimulateWritesThroughAPipeInsteadOfReplacingIt) {
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  const Outcome r = run_command("(cat " + path("pipe") + " > " + path("got.csv") + " &) ; " +
                                    shell_quote(hamel_binary()) + " simulate " + path("spring.yaml") +
                                    " --t-end 1 --sample 0.5 --init x=1 --out " + path("pipe") + "; sleep 0.2",
                                dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(dir / "pipe"))) << "the named pipe was replaced";
  EXPECT_EQ(slurp(dir / "got.csv").rfind("t,x,u\n", 0), 0u) << slurp(dir / "got.csv");
  EXPECT_FALSE(has_temporaries(dir));
}

TEST_F(Output, SimulateKeepsASymbolicLinkAndReplacesItsTarget) {
  spit(dir / "real.csv", "old\n");
  fs::create_symlink("real.csv", dir / "link.csv");
  const Outcome r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out " + path("link.csv"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "link.csv")));
  EXPECT_EQ(slurp(dir / "real.csv").rfind("t,x,u\n", 0), 0u);
  EXPECT_FALSE(has_temporaries(dir));
}

TEST_F(Output, WriteErrorsExitWithStatusOne) {
  if (!fs::is_character_file("/dev/full")) GTEST_SKIP() << "no /dev/full";
  // The redirection is inside a subshell: run_command's own redirection of stdout comes after it.
  const std::string hamel_path = shell_quote(hamel_binary());
  Outcome r =
      run_command("(" + hamel_path + " simulate " + path("spring.yaml") + " --t-end 1 --out - > /dev/full)", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write standard output"), std::string::npos) << r.err;
  r = run_command("(" + hamel_path + " derive " + path("spring.yaml") + " > /dev/full)", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  r = run_command("(" + hamel_path + " derive --json " + path("spring.yaml") + " > /dev/full)", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  // --out naming the device: written through (the device stays a device), and the error is reported.
  r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out /dev/full", dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status("/dev/full")));
  EXPECT_FALSE(has_temporaries(dir));
}

TEST_F(Output, EmitRefusesAFolderWhoseFilesMerelyClaimToBeGenerated) {
  fs::create_directories(dir / "pkg");
  spit(dir / "pkg" / "notes.txt", "// Generated by hamel -- my own notes\n");
  Outcome r = hamel("emit " + path("spring.yaml") + " -o " + path("pkg"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("'notes.txt', which hamel did not write"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "pkg" / "notes.txt"), "// Generated by hamel -- my own notes\n");

  // A package hamel wrote (it carries the manifest) is replaced; one whose file was edited is not.
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir).status, 0);
  EXPECT_TRUE(fs::is_regular_file(dir / "out" / ".hamel-manifest"));
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir).status, 0);
  spit(dir / "out" / "spring.cpp", slurp(dir / "out" / "spring.cpp") + "// my fix\n");
  r = hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("changed since hamel wrote it"), std::string::npos) << r.err;
  EXPECT_NE(slurp(dir / "out" / "spring.cpp").find("// my fix"), std::string::npos);
  // Beside a manifest, a file it does not list is foreign too.
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out2"), dir).status, 0);
  spit(dir / "out2" / "spring.hpp.orig", "x\n");
  r = hamel("emit " + path("spring.yaml") + " -o " + path("out2"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out2" / "spring.hpp.orig"));
  EXPECT_FALSE(has_temporaries(dir));
}

// A folder emit refuses is refused before the derivation (which takes minutes for large models), not after.
TEST_F(Output, EmitRefusesTheFolderBeforeDeriving) {
  fs::create_directories(dir / "pkg");
  spit(dir / "pkg" / "mine.txt", "x\n");
  Outcome r = hamel("emit " + path("spring.yaml") + " -o " + path("pkg"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("'mine.txt', which hamel did not write"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("deriving"), std::string::npos) << r.err;
  spit(dir / "a_file", "x\n");
  r = hamel("emit " + path("spring.yaml") + " -o " + path("a_file"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("exists and is not a folder"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("deriving"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "a_file"), "x\n");
  // A folder an earlier emit wrote still passes the early check and is replaced.
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir).status, 0);
  r = hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("deriving"), std::string::npos) << r.err;
  EXPECT_FALSE(has_temporaries(dir));
}

// The package README builds out of tree, so that following it leaves a folder emit may still replace: its
// cmake commands, run as written from the folder holding the package, create nothing inside the package.
TEST_F(Output, PackageReadmeBuildsOutOfTreeAndEmitStillReplacesThePackage) {
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("spring"), dir).status, 0);
  const std::string readme = slurp(dir / "spring" / "README.md");
  EXPECT_EQ(readme.find("-S ."), std::string::npos);
  const std::size_t at = readme.find("\ncmake -S spring -B spring-build ");
  ASSERT_NE(at, std::string::npos) << readme;
  const std::string configure = readme.substr(at + 1, readme.find('#', at) - at - 1);
  Outcome r = run_command("cd " + shell_quote(dir.string()) + " && " + configure, dir);
  ASSERT_EQ(r.status, 0) << configure << "\n" << r.out << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "spring-build" / "CMakeCache.txt"));
  EXPECT_EQ(names_in(dir / "spring"), (std::set<std::string>{".hamel-manifest", "CMakeLists.txt", "README.md",
                                                             "spring.cpp", "spring.h", "spring.hpp"}));
  r = hamel("emit " + path("spring.yaml") + " -o " + path("spring"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(dir / "spring" / "CMakeLists.txt").find("-B spring-build"), std::string::npos);
}

// Re-emitting into an existing package and killing the process at times spread over the whole run (with
// SIGKILL nothing can clean up): the folder must always hold a whole package, the old one or the new one.
TEST_F(Output, KilledReEmitNeverLeavesTheFolderMissing) {
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir).status, 0);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(wait_status(start_hamel({"emit", (dir / "spring.yaml").string(), "-o", (dir / "out").string()}, dir / ".o",
                                    dir / ".e")),
            0);
  const double run_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (int k = 0; k < 24; ++k) {
    const pid_t pid =
        start_hamel({"emit", (dir / "spring.yaml").string(), "-o", (dir / "out").string()}, dir / ".o", dir / ".e");
    std::this_thread::sleep_for(std::chrono::microseconds(static_cast<long>(run_ms * 1000 * (0.6 + 0.02 * k))));
    ::kill(pid, SIGKILL);
    wait_status(pid);
    ASSERT_TRUE(fs::is_regular_file(dir / "out" / "spring.hpp")) << "kill " << k << " left no package";
    ASSERT_TRUE(fs::is_regular_file(dir / "out" / ".hamel-manifest")) << "kill " << k;
  }
  // The next run sweeps what the killed ones left (their processes are gone).
  ASSERT_EQ(hamel("emit " + path("spring.yaml") + " -o " + path("out"), dir).status, 0);
  EXPECT_FALSE(has_temporaries(dir)) << "stale temporaries were not swept";
}

TEST_F(Output, InterruptedSimulateRemovesItsTemporaryAndKeepsTheOldFile) {
  for (int sig : {SIGINT, SIGTERM}) {
    spit(dir / "old.csv", "t,x,u\n");
    const pid_t pid = start_hamel({"simulate", (dir / "spring.yaml").string(), "--t-end", "1000", "--integrator", "rk4",
                                   "--dt", "1e-4", "--init", "x=1", "--out", (dir / "old.csv").string()},
                                  dir / ".o", dir / ".e");
    // Wait until the temporary file exists and is growing, then interrupt.
    for (int k = 0; k < 200 && !has_temporaries(dir); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_TRUE(has_temporaries(dir)) << slurp(dir / ".e");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(pid, sig);
    EXPECT_EQ(wait_status(pid), 128 + sig);
    EXPECT_EQ(slurp(dir / "old.csv"), "t,x,u\n");
    EXPECT_FALSE(has_temporaries(dir)) << "signal " << sig;
  }
}

TEST_F(Output, StaleTemporariesOfDeadProcessesAreSweptOthersKept) {
  // pid 1 is alive; a pid beyond pid_max never is; a name without a pid is not ours to remove.
  spit(dir / "x.csv.tmp-1-7", "running\n");
  spit(dir / "x.csv.tmp-2147483647-7", "stale\n");
  spit(dir / "x.csv.tmp-mine", "user\n");
  const Outcome r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out " + path("x.csv"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "x.csv.tmp-1-7"));
  EXPECT_FALSE(fs::exists(dir / "x.csv.tmp-2147483647-7"));
  EXPECT_TRUE(fs::exists(dir / "x.csv.tmp-mine"));
}

// The description reaches the package README only inert: no ESC, no C1 CSI (U+009B), no bidi override
// (U+202E), no HTML.
TEST_F(Output, DescriptionInTheReadmeIsInert) {
  spit(dir / "d.yaml", std::string(spring) +
                           "description: \"red \\e[31m csi \\u009B2J flip \\u202E <script>alert(1)</script> & ok\"\n");
  const Outcome r = hamel("emit " + path("d.yaml") + " -o " + path("pkg"), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string readme = slurp(dir / "pkg" / "README.md");
  EXPECT_NE(readme.find("red [31m csi 2J flip &lt;script&gt;alert(1)&lt;/script&gt; &amp; ok"), std::string::npos)
      << readme;
  EXPECT_EQ(readme.find('\x1b'), std::string::npos);
  EXPECT_EQ(readme.find("\xc2\x9b"), std::string::npos);
  EXPECT_EQ(readme.find("\xe2\x80\xae"), std::string::npos);
  EXPECT_EQ(readme.find("<script>"), std::string::npos);
}

// Paths from the command line are printed escaped: a newline in -o cannot forge a line on stderr.
TEST_F(Output, OutputPathIsPrintedEscaped) {
  const Outcome r = hamel("emit " + path("spring.yaml") + " -o " + shell_quote((dir / "a\nb").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("a\\nb/"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("a\nb"), std::string::npos) << r.err;
}

// Inputs are bounded too: `hamel derive /dev/zero` grew to 4.6 GB before this was refused.
TEST_F(Output, ModelFilesMustBeSmallRegularFiles) {
  Outcome r = hamel("derive /dev/zero", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("/dev/zero: error: the model file is not a regular file"), std::string::npos) << r.err;
  spit(dir / "scene.yaml", "scene: s\nmodel: /dev/zero\n");
  r = hamel("simulate " + path("scene.yaml") + " --t-end 1 --out " + path("x.csv"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
  spit(dir / "big.yaml", std::string(spring) + "# " + std::string(1 << 20, 'x') + "\n");
  r = hamel("derive " + path("big.yaml"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("more than the limit of 1048576"), std::string::npos) << r.err;
}

}  // namespace
