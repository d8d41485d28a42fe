// Every bad input, signal and resource limit meets the contract of docs/cli.md:
// the documented exit code, exactly one line on stderr ("microcobot: error: ..."), no NaN on
// stdout, nothing new left in --out on failure, and bounded time. Each case is a regression
// test for a cause a hostile user can hit.

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"

extern char** environ;

namespace mc {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::run_cli;
using test::TempDir;
using test::write_text;
using ::testing::HasSubstr;
using ::testing::Not;

// "Promptly": what a refused or bounded command takes, with room for a sanitized build on a loaded
// machine (a process start there takes a second); the unbounded work these tests guard against
// (an endless loop, a quadratic parse, a run past the work budget) takes minutes.
constexpr double kPromptly_s = 15.0;

struct Timed {
  test::CliResult r;
  double wall_s = 0.0;
};

Timed timed(const std::vector<std::string>& args) {
  const auto t0 = std::chrono::steady_clock::now();
  Timed t{run_cli(args), 0.0};
  t.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

std::string joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += a + " ";
  return s;
}

// The contract of a failing command: exit code, one line on stderr, nothing on stdout that
// could be taken for a result, bounded time.
void expect_error(const std::vector<std::string>& args, int code, const std::string& needle = {},
                  double max_wall_s = 20.0) {
  const auto t = timed(args);
  EXPECT_EQ(t.r.exit_code, code) << joined(args) << "\n" << t.r.err;
  EXPECT_EQ(line_count(t.r.err), 1u) << joined(args) << "\n" << t.r.err;
  EXPECT_THAT(t.r.err, ::testing::StartsWith("microcobot: error: ")) << joined(args);
  if (!needle.empty()) {
    EXPECT_THAT(t.r.err, HasSubstr(needle)) << joined(args);
  }
  EXPECT_LE(t.r.err.size(), 600u) << joined(args);
  EXPECT_THAT(t.r.out, Not(HasSubstr("nan"))) << joined(args);
  EXPECT_LT(t.wall_s, max_wall_s) << joined(args);
}

std::size_t entries(const fs::path& dir) {
  std::size_t n = 0;
  for (auto it = fs::directory_iterator(dir); it != fs::directory_iterator(); ++it) ++n;
  return n;
}

// ---- 1. crashes ------------------------------------------------------------------------------

TEST(Hardening, FftOfLengthOneIsAnErrorNotACrash) {
  TempDir d;
  write_text(d / "one.csv", "t_s,u_V\n0,1\n");
  write_text(d / "two.csv", "t_s,u_V\n0,1\n1,2\n3,4\n");
  expect_error({"dsp", "welch", "--in", (d / "one.csv").string(), "--column", "u_V", "--fs", "1000"}, 3,
               "at least 2 samples");
  expect_error(
      {"dsp", "welch", "--in", (d / "two.csv").string(), "--column", "u_V", "--fs", "1000", "--nperseg", "1"},
      3, "nperseg");
  expect_error({"dsp", "frf", "--in", (d / "two.csv").string(), "--input", "t_s", "--output", "u_V", "--fs",
                "1000", "--nperseg", "1"},
               3, "nperseg");
  expect_error({"dsp", "welch", "--in", (d / "two.csv").string(), "--column", "u_V", "--fs", "1000", "--nfft",
                "4000000000"},
               3, "nfft", kPromptly_s);
}

// ---- 2. input files ---------------------------------------------------------------------------

TEST(Hardening, InputFilesMustBeRegularFiles) {
  TempDir d;
  fs::create_directory(d / "dir");
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0600), 0);
  for (const std::string& bad : {std::string("/dev/zero"), (d / "dir").string(), (d / "fifo").string()}) {
    expect_error({"stickslip", "params", "--params", bad}, 3, bad, kPromptly_s);
    expect_error({"run", "--config", bad, "--print-config"}, 3, bad, kPromptly_s);
    expect_error({"dsp", "welch", "--in", bad, "--column", "u_V", "--fs", "1"}, 3, bad, kPromptly_s);
  }
  expect_error({"dsp", "welch", "--in", (d / "dir").string(), "--column", "u_V", "--fs", "1"}, 3,
               "is a directory");
  // stickslip_params_file inside a configuration.
  write_text(d / "c.yaml", "stickslip_params_file: " + (d / "dir").string() + "\n");
  expect_error({"run", "--config", (d / "c.yaml").string(), "--duration", "1"}, 3, "is a directory");
}

TEST(Hardening, ParameterFilesHaveASizeCap) {
  TempDir d;
  write_text(d / "big.yaml", "# " + std::string(2u << 20, 'x') + "\n");
  expect_error({"stickslip", "params", "--params", (d / "big.yaml").string()}, 3, "too large");
}

TEST(Hardening, YamlRejectsDuplicateKeysAndExtraDocuments) {
  TempDir d;
  write_text(d / "dup.yaml",
             "friction:\n  rho0_a_N_m: 3.5e5\nslider:\n  mass_kg: 0.02\nfriction:\n  rho1_a_N_s_m: 60\n");
  expect_error({"stickslip", "params", "--params", (d / "dup.yaml").string()}, 3,
               "dup.yaml:5: duplicate key 'friction'");
  write_text(d / "dup2.yaml", "slider:\n  mass_kg: 0.02\n  mass_kg: 0.03\n");
  expect_error({"stickslip", "params", "--params", (d / "dup2.yaml").string()}, 3,
               ":3: duplicate key 'mass_kg'");
  write_text(d / "two.yaml", "slider:\n  mass_kg: 0.02\n---\nslider:\n  mass_kg: 0.03\n");
  expect_error({"stickslip", "params", "--params", (d / "two.yaml").string()}, 3, "second YAML document");
  // Found by the parameter fuzzer: yaml-cpp's LoadAll() looped forever on a lone ','.
  for (const char* text : {",", "\n,\x02", "  base_rate_Hz: 10<00\n,stikcslip_pa :e\xa2 _l"}) {
    write_text(d / "comma.yaml", text);
    const auto t = timed({"stickslip", "params", "--params", (d / "comma.yaml").string()});
    EXPECT_LT(t.wall_s, kPromptly_s) << text;
    EXPECT_EQ(line_count(t.r.err), t.r.exit_code == 0 ? 0u : 1u) << t.r.err;
  }
  // Found by the configuration fuzzer: an unknown key of raw bytes was echoed raw, with every
  // known key after it.
  write_text(d / "bytes.yaml", "tweezers: {\xff\xff\xff\xff: 1}\n");
  expect_error({"run", "--config", (d / "bytes.yaml").string(), "--print-config"}, 3, "\\xff");
  write_text(d / "dupc.yaml", "loop:\n  base_rate_Hz: 10000\nloop:\n  base_rate_Hz: 10000\n");
  expect_error({"run", "--config", (d / "dupc.yaml").string(), "--print-config"}, 3, "duplicate key 'loop'");
}

// ---- 3. work budgets --------------------------------------------------------------------------

TEST(Hardening, WorkBudgetsAreCheckedBeforeTheRun) {
  TempDir d;
  expect_error(
      {"control", "trajectory", "--distance", "0.012", "--velocity", "1e-7", "--acceleration", "1e-6"}, 3,
      "work budget", kPromptly_s);
  write_text(d / "id.yaml", "identify:\n  duration_s: 100000\n");
  expect_error({"tweezers", "identify", "--params", (d / "id.yaml").string()}, 3, "identify.duration_s",
               kPromptly_s);
  expect_error({"tweezers", "virtual-cube", "--rate", "1e9"}, 3, "plant_rate_Hz", kPromptly_s);
  write_text(d / "cube.yaml", "cube:\n  plant_rate_Hz: 1e12\n");
  expect_error({"tweezers", "virtual-cube", "--params", (d / "cube.yaml").string()}, 3, "plant_rate_Hz",
               kPromptly_s);
  write_text(d / "trap.yaml", "trap:\n  dt_s: 1e-12\n");
  expect_error({"haptics", "tweezers", "--params", (d / "trap.yaml").string()}, 3, "dt_s", kPromptly_s);
  expect_error({"stickslip", "simulate", "--duration", "1e4"}, 3, "work budget", kPromptly_s);
}

TEST(Hardening, ControlValidateNamesItsFlags) {
  // The validation set cannot be drawn with the tuning set's seed (the sets are kept apart).
  expect_error({"control", "validate", "--seed", "15"}, 3, "--seed", kPromptly_s);
  expect_error({"control", "validate", "--set", "all"}, 2, "--set", kPromptly_s);
  expect_error({"control", "validate", "--cases", "0"}, 2, "--cases", kPromptly_s);
}

TEST(Hardening, WideCsvHeaderIsLinear) {
  TempDir d;
  std::string header, row;
  for (int i = 0; i < 200000; ++i) {
    header += (i ? ",c" : "c") + std::to_string(i);
    row += i ? ",1" : "1";
  }
  write_text(d / "wide.csv", header + "\n" + row + "\n" + row + "\n");
  const auto t = timed({"dsp", "welch", "--in", (d / "wide.csv").string(), "--column", "c7", "--fs", "1"});
  EXPECT_EQ(t.r.exit_code, 0) << t.r.err;
  EXPECT_LT(t.wall_s, kPromptly_s);
}

// ---- 4. stability limits ----------------------------------------------------------------------

TEST(Hardening, ContactTooStiffForTheStepIsRefused) {
  TempDir d;
  for (const char* v : {"1e9", "1e12", "1e308"}) {
    write_text(d / "stiff.yaml", std::string("friction:\n  rho0_a_N_m: ") + v + "\n");
    expect_error({"stickslip", "simulate", "--params", (d / "stiff.yaml").string()}, 3, "friction.rho0_a_N_m",
                 kPromptly_s);
    const auto r = run_cli({"stickslip", "simulate", "--params", (d / "stiff.yaml").string()});
    EXPECT_THAT(r.err, HasSubstr("largest value"));
    write_text(d / "cstiff.yaml", std::string("model:\n  friction:\n    rho0_a_N_m: ") + v + "\n");
    expect_error({"control", "velocity", "--params", (d / "cstiff.yaml").string()}, 3, "friction.rho0_a_N_m",
                 kPromptly_s);
    write_text(d / "c.yaml", "stickslip_params_file: " + (d / "stiff.yaml").string() + "\n");
    expect_error({"run", "--config", (d / "c.yaml").string(), "--duration", "1"}, 3, "friction.rho0_a_N_m",
                 kPromptly_s);
  }
  write_text(d / "kc.yaml", "friction:\n  coupling_stiffness_N_m: 1e9\n");
  expect_error({"stickslip", "simulate", "--params", (d / "kc.yaml").string()}, 3, "coupling_stiffness_N_m");
  // The defaults are accepted at the largest step the integrator allows.
  for (const char* dt : {"1e-4", "1e-5", "1e-7"}) {
    const auto r = run_cli({"stickslip", "simulate", "--duration", "0.02", "--dt", dt, "--json"});
    EXPECT_EQ(r.exit_code, 0) << dt << ": " << r.err;
  }
}

// ---- 5. exit codes and messages ---------------------------------------------------------------

TEST(Hardening, GroupsWithoutAVerbAreUsageErrors) {
  for (const char* g : {"stickslip", "control", "haptics", "dsp", "tweezers", "identify", "design"}) {
    expect_error({g}, 2, "verb");
  }
  expect_error({"stickslip"}, 2, "simulate");
  expect_error({"frobnicate"}, 2, "'frobnicate'");
  expect_error({"stickslip", "frobnicate"}, 2, "'frobnicate'");
}

TEST(Hardening, OneExitCodePerKindOfError) {
  expect_error({"run", "--config", "missing.yaml"}, 3, "missing.yaml");
  expect_error({"stickslip", "params", "--params", "missing.yaml"}, 3, "missing.yaml");
  for (const char* v : {"nan", "inf", "-inf", "NaN"}) {
    expect_error({"stickslip", "simulate", "--duration", v}, 2, "finite");
    expect_error({"dsp", "butter", "--fc", v, "--fs", "1000"}, 2, "finite");
  }
  expect_error({"run", "--scenario", "nope"}, 2, "--scenario");
}

TEST(Hardening, NumbersInMessagesAreShort) {
  const auto r = run_cli({"stickslip", "simulate", "--dt", "1e-10"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("1e-09"));
  EXPECT_THAT(r.err, Not(HasSubstr("0.000000")));
  const auto big = run_cli({"stickslip", "simulate", "--duration", "1.7976931348623157e308"});
  EXPECT_NE(big.exit_code, 0);
  EXPECT_LT(big.err.size(), 300u) << big.err;
}

TEST(Hardening, MessagesBlameWhatWasGiven) {
  TempDir d;
  // A slew rate far out of scale is named, not the frequency it makes too high.
  write_text(d.path() / "slew.yaml", "drive: {slew_rate_V_s: 1.0e-300}\n");
  expect_error({"stickslip", "simulate", "--params", (d.path() / "slew.yaml").string()}, 3,
               "drive.slew_rate_V_s");
  // `dsp octave --fmin` above the data: the data's end, not a --fmax that was never given.
  write_text(d.path() / "frf.csv", "f_Hz,re,im\n10,1,0\n20,1,0\n40,1,0\n");
  const auto frf = (d.path() / "frf.csv").string();
  expect_error({"dsp", "octave", "--in", frf, "--fmin", "1000"}, 2, "the data's highest frequency (40 Hz)");
  const auto r = run_cli({"dsp", "octave", "--in", frf, "--fmin", "1000"});
  EXPECT_THAT(r.err, Not(HasSubstr("--fmax")));
}

TEST(Hardening, CsvEchoIsCutAndEscaped) {
  TempDir d;
  write_text(d / "long.csv", "t_s,u_V\n0," + std::string(100000, 'x') + "\n");
  expect_error({"dsp", "welch", "--in", (d / "long.csv").string(), "--column", "u_V", "--fs", "1"}, 3, "...");
  write_text(d / "bin.csv", std::string("t_s,u_V\n0,\x01\x02\xff\x1b[31m\n", 18));
  expect_error({"dsp", "welch", "--in", (d / "bin.csv").string(), "--column", "u_V", "--fs", "1"}, 3,
               "\\x01");
}

TEST(Hardening, CsvBomAndLineEndings) {
  TempDir d;
  std::string rows;
  for (int i = 0; i < 64; ++i) rows += std::to_string(i) + "," + std::to_string(i % 7) + "\r";
  write_text(d / "bom.csv", "\xEF\xBB\xBFt_s,u_V\n0,1\n1,2\n2,0\n3,1\n");
  write_text(d / "cr.csv", "t_s,u_V\r" + rows);
  for (const char* f : {"bom.csv", "cr.csv"}) {
    const auto r =
        run_cli({"dsp", "welch", "--in", (d / f).string(), "--column", "u_V", "--fs", "1", "--json"});
    EXPECT_EQ(r.exit_code, 0) << f << ": " << r.err;
  }
}

// ---- 6. whole-command atomicity and signals ---------------------------------------------------

TEST(Hardening, AFailedCommandLeavesNothingInOut) {
  TempDir d;
  write_text(d / "stiff.yaml", "friction:\n  rho0_a_N_m: 1e9\n");
  expect_error(
      {"stickslip", "simulate", "--params", (d / "stiff.yaml").string(), "--out", (d / "o").string()}, 3);
  EXPECT_FALSE(fs::exists(d / "o"));
  EXPECT_EQ(entries(d.path()), 1u);  // only stiff.yaml: no staging directory either
  // A directory in the way of index.html: refused before anything is moved into place.
  fs::create_directories(d / "r" / "index.html");
  expect_error({"report", "--only", "rng", "--out", (d / "r").string()}, 3, "index.html");
  EXPECT_EQ(entries(d / "r"), 1u);
  // A run too short for its report is refused up front, and leaves no recording.
  expect_error({"run", "--duration", "1e-9", "--out", (d / "s").string()}, 2, "--duration");
  EXPECT_FALSE(fs::exists(d / "s"));
}

TEST(Hardening, ASuccessfulCommandNamesItsFinalPaths) {
  TempDir d;
  const auto r = run_cli({"report", "--only", "rng", "--out", (d / "r").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr((d / "r" / "index.html").string()));
  EXPECT_THAT(r.out, Not(HasSubstr(".tmp-")));
  EXPECT_TRUE(fs::exists(d / "r" / "index.html"));
  EXPECT_EQ(entries(d.path()), 1u);
}

struct Spawned {
  pid_t pid = 0;
  fs::path err;
};

Spawned spawn(const std::vector<std::string>& args, const fs::path& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> argv_s{MC_CLI_PATH};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  Spawned s;
  s.err = err;
  EXPECT_EQ(posix_spawn(&s.pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  return s;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST(Hardening, SignalsRemoveTemporariesAndExit130Or143) {
  TempDir d;
  // A long computation with --out: the staging directory goes with it.
  auto s = spawn(
      {"control", "trajectory", "--profile", "sine", "--frequency", "0.005", "--out", (d / "o").string()},
      d / "err");
  // Once its staging directory stands beside err (the signal handlers are in place before the
  // command line is parsed, --out is staged while it is parsed).
  ASSERT_TRUE(test::eventually([&] { return entries(d.path()) >= 2; }, std::chrono::seconds(60)))
      << test::read_text(d / "err");
  ::kill(s.pid, SIGINT);
  EXPECT_EQ(wait_exit(s.pid), 130);
  const auto err = test::read_text(d / "err");
  EXPECT_EQ(line_count(err), 1u) << err;
  EXPECT_THAT(err, HasSubstr("SIGINT"));
  EXPECT_FALSE(fs::exists(d / "o"));
  EXPECT_EQ(entries(d.path()), 1u);  // only err
}

// The threads of a running process (its /proc status' "Threads:"); 0 once it is gone.
int thread_count(pid_t pid) {
  const std::string status = test::read_text("/proc/" + std::to_string(pid) + "/status");
  const auto at = status.find("Threads:");
  return at == std::string::npos ? 0 : std::atoi(status.c_str() + at + 8);
}

TEST(Hardening, AnInterruptedRunKeepsAMarkedRecording) {
  TempDir d;
  // --realtime paces the simulated 37 s to the wall clock: the signal comes mid-run, once the
  // session's threads run (the command takes signals as a stop from before it builds them).
  auto s = spawn({"run", "--realtime", "--out", (d / "s").string()}, d / "err");
  ASSERT_TRUE(test::eventually([&] { return thread_count(s.pid) >= 2; }, std::chrono::seconds(60)))
      << test::read_text(d / "err");
  ::kill(s.pid, SIGTERM);
  EXPECT_EQ(wait_exit(s.pid), 143);
  const auto err = test::read_text(d / "err");
  EXPECT_EQ(line_count(err), 1u) << err;
  EXPECT_THAT(err, HasSubstr("SIGTERM"));
  ASSERT_TRUE(fs::exists(d / "s" / "recording.csv"));
  EXPECT_TRUE(fs::exists(d / "s" / "index.html"));
  EXPECT_TRUE(fs::exists(d / "s" / "recording.mcap"));
  const auto rec = test::read_text(d / "s" / "recording.csv");
  EXPECT_THAT(rec.substr(0, 200), HasSubstr("# interrupted at t = "));
}

}  // namespace
}  // namespace mc
