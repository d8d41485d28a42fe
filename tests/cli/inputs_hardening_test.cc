// Bad inputs at the edge of the contract of docs/cli.md, each a regression test: stiffnesses beyond what
// their step resolves, an overflowing FRF, --save onto the measurement, --out on a mount point, a signal
// while outputs are written, messages that named internal quantities, absurd `run` scenes.

#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <cmath>
#include <csignal>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"

namespace mc {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace inputs_hardening_test {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::run_cli;
using test::TempDir;
using test::write_text;
using ::testing::HasSubstr;
using ::testing::Not;

std::string joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += a + " ";
  return s;
}

// A failing command: its exit code, one line on stderr naming `needle`, in bounded time (the refused
// runs would otherwise take seconds to minutes). Returns stderr.
std::string expect_error(const std::vector<std::string>& args, int code, const std::string& needle) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run_cli(args);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exit_code, code) << joined(args) << "\n" << r.err;
  EXPECT_EQ(line_count(r.err), 1u) << joined(args) << "\n" << r.err;
  EXPECT_THAT(r.err, ::testing::StartsWith("microcobot: error: ")) << joined(args);
  EXPECT_THAT(r.err, HasSubstr(needle)) << joined(args);
  EXPECT_THAT(r.out, Not(HasSubstr("nan"))) << joined(args);
  EXPECT_LT(wall_s, 15.0) << joined(args);
  return r.err;
}

std::size_t entries(const fs::path& dir) {
  std::size_t n = 0;
  for (auto it = fs::directory_iterator(dir); it != fs::directory_iterator(); ++it) ++n;
  return n;
}

TEST(InputsHardening, StiffnessesAreCheckedAgainstWhatTheirStepResolves) {
  TempDir d;
  // The virtual cube: 1e308 N/m reported "chatter": false with wall forces of 2e303 N.
  write_text(d / "cube.yaml", "cube:\n  stiffness_N_per_m: 1e308\n");
  auto err = expect_error({"tweezers", "virtual-cube", "--params", (d / "cube.yaml").string(), "--json"}, 3,
                          "stiffness_N_per_m");
  EXPECT_THAT(err, HasSubstr("largest value"));
  expect_error({"tweezers", "virtual-cube", "--stiffness", "1e308", "--json"}, 3, "--stiffness");
  expect_error({"tweezers", "virtual-cube", "--stiffness", "1e6", "--no-compensator", "--json"}, 3,
               "--stiffness");
  // The optical trap: 1e-2 N/m relaxes within dt_s; 1e-3 N/m puts its corner (6.6 kHz) beyond the
  // 10 kHz record's Nyquist frequency (it fitted a corner 7 % low, exit 0).
  for (const char* k : {"1e-2", "1e-3"}) {
    write_text(d / "trap.yaml", std::string("trap:\n  trap_stiffness_N_per_m: ") + k + "\n");
    err = expect_error({"haptics", "tweezers", "--params", (d / "trap.yaml").string(), "--json"}, 3,
                       "trap_stiffness_N_per_m");
    EXPECT_THAT(err, HasSubstr("largest value")) << k;
  }
  // The manual mode's object on the tip (it diverged, exit 4, or held nonsense forces, exit 0).
  for (const char* k : {"2e5", "1e308"}) {
    write_text(d / "manual.yaml", std::string("manual:\n  object_stiffness_N_per_m: ") + k + "\n");
    expect_error({"tweezers", "manual", "--params", (d / "manual.yaml").string(), "--json"}, 3,
                 "object_stiffness_N_per_m");
  }
  // The dual-stage plant's links (exact ZOH): 1e308 N/m overflowed the exponential ("diverged", exit 4).
  for (const char* key : {"k_2_N_per_m", "k_d_N_per_m"}) {
    write_text(d / "plant.yaml", std::string("plant:\n  ") + key + ": 1e308\n");
    err = expect_error({"haptics", "evaluate", "--params", (d / "plant.yaml").string(), "--json"}, 3, key);
    EXPECT_THAT(err, HasSubstr("largest value")) << key;
  }
  // The defaults and the documented study stay accepted.
  for (const std::vector<std::string>& ok :
       {std::vector<std::string>{"tweezers", "virtual-cube", "--json"},
        {"tweezers", "virtual-cube", "--stiffness", "16000", "--no-compensator", "--json"},
        {"tweezers", "manual", "--json"},
        {"haptics", "tweezers", "--json"},
        {"haptics", "evaluate", "--json"}}) {
    const auto r = run_cli(ok);
    EXPECT_EQ(r.exit_code, 0) << joined(ok) << r.err;
  }
}

TEST(InputsHardening, OverflowingSpectraFailNamingTheFileAndColumn) {
  TempDir d;
  std::string csv = "t_s,u_V,x_m\n";
  for (int i = 0; i < 512; ++i) {
    csv += std::to_string(i * 1e-6) + "," + std::to_string(std::sin(0.3 * i)) + "e308," +
           std::to_string(std::sin(0.3 * i + 1)) + "e308\n";
  }
  write_text(d / "big.csv", csv);
  const auto big = (d / "big.csv").string();
  // `dsp frf` reported H = 0 and coherence 0 (exit 0); it now fails as `dsp welch` does.
  expect_error({"dsp", "frf", "--in", big, "--input", "u_V", "--output", "x_m", "--fs", "1e6", "--json"}, 4,
               "column 'u_V': the power spectrum overflows");
  expect_error({"dsp", "welch", "--in", big, "--column", "x_m", "--fs", "1e6", "--json"}, 4,
               "column 'x_m': the power spectrum overflows");
  // Identification blamed its peak finder for a non-finite value the (finite) data did not hold.
  for (const char* verb : {"pe-modes", "friction-modes"}) {
    const auto err = expect_error({"identify", verb, "--in", big}, 3, "big.csv: column 'x_m'");
    EXPECT_THAT(err, Not(HasSubstr("find_peaks")));
  }
}

TEST(InputsHardening, ErrorsBlameTheFlagOrColumnAtFault) {
  TempDir d;
  std::string sig = "t_s,y\n", one = "t_s,y\n0,1\n", zero = "f_Hz,re,im\n", dc = "f_Hz,re,im\n0,1,0\n";
  for (int i = 0; i < 2000; ++i)
    sig += std::to_string(i * 1e-3) + "," + std::to_string(std::sin(0.3 * i)) + "\n";
  for (int i = 1; i <= 50; ++i) zero += std::to_string(2.0 * i) + ",0,0\n";
  // A step response whose position is fine and whose drive holds 1e308 V once.
  std::string step = "t_s,u_V,x_m\n";
  for (int i = 0; i < 7500; ++i) {
    const double t = i * 4e-5, on = t > 0.002 ? 1.0 : 0.0;
    const double x = on * 1e-7 * (1 - std::exp(-(t - 0.002) * 30) * std::cos(2 * M_PI * 55 * (t - 0.002)));
    step += fmt::format("{},{},{}\n", t, i == 1000 ? 1e308 : 50.0 * on, x);
  }
  write_text(d / "sig.csv", sig);
  write_text(d / "one.csv", one);
  write_text(d / "zero.csv", zero);
  write_text(d / "dc.csv", dc);
  write_text(d / "step.csv", step);
  // A rate near the smallest double overflows the density: --fs, not the spectrum's values.
  auto err =
      expect_error({"dsp", "welch", "--in", (d / "sig.csv").string(), "--column", "y", "--fs", "1e-310"}, 3,
                   "--fs: too small");
  EXPECT_THAT(err, Not(HasSubstr("overflows (values")));
  // One sample: the file and column, not the library's argument "x".
  err = expect_error({"dsp", "welch", "--in", (d / "one.csv").string(), "--column", "y", "--fs", "1000"}, 3,
                     "one.csv: column 'y': signal must have at least 2 samples");
  EXPECT_THAT(err, Not(HasSubstr("parameter x")));
  // A response zero everywhere: the data, not --fmin.
  err = expect_error({"dsp", "tffit", "--in", (d / "zero.csv").string()}, 3, "the response is zero at 50");
  EXPECT_THAT(err, Not(HasSubstr("fmin")));
  // Data at DC alone: no band, not an infinite lowest frequency.
  err = expect_error({"dsp", "octave", "--in", (d / "dc.csv").string()}, 3, "no positive frequency");
  EXPECT_THAT(err, Not(HasSubstr("inf")));
  // The drive's column holds the absurd value: u_V is blamed, not x_m.
  expect_error({"identify", "friction-modes", "--in", (d / "step.csv").string()}, 3, "column 'u_V'");
  // --save naming a directory: said so, not "disk full".
  fs::create_directory(d / "dir");
  err = expect_error(
      {"identify", "friction-modes", "--in", (d / "step.csv").string(), "--save", (d / "dir").string()}, 2,
      "is a directory");
  EXPECT_THAT(err, Not(HasSubstr("disk full")));
}

TEST(InputsHardening, SaveOntoTheMeasurementIsRefused) {
  TempDir d;
  const std::string rec = "t_s,u_V,x_m\n0,0,0\n1,0,0\n";
  write_text(d / "rec.csv", rec);
  // Named directly or through another spelling of the same file: refused, the data untouched.
  for (const fs::path& save : {d / "rec.csv", d.path() / "." / "rec.csv"}) {
    expect_error({"identify", "pe-modes", "--in", (d / "rec.csv").string(), "--save", save.string()}, 2,
                 "is the --in file");
    EXPECT_EQ(test::read_text(d / "rec.csv"), rec);
  }
  // A measurement of an --in directory.
  fs::create_directory(d / "campaign");
  write_text(d / "campaign" / "step.csv", rec);
  expect_error({"identify", "all", "--in", (d / "campaign").string(), "--save",
                (d / "campaign" / "step.csv").string()},
               2, "measurement in the --in directory");
  EXPECT_EQ(test::read_text(d / "campaign" / "step.csv"), rec);
}

// A tmpfs mounted on DIR for the test's life; mounting needs privileges (root, as CI runs).
struct Mounted {
  fs::path dir;
  bool ok = false;
  explicit Mounted(fs::path d) : dir(std::move(d)) {
    fs::create_directories(dir);
    ok = ::mount("none", dir.c_str(), "tmpfs", 0, "size=16m") == 0;
  }
  ~Mounted() {
    if (ok) ::umount2(dir.c_str(), MNT_DETACH);
  }
};

TEST(InputsHardening, AnOutThatIsAMountPointIsStagedOnItsOwnFileSystem) {
  TempDir d;
  const Mounted m(d / "mnt");
  if (!m.ok) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  // Staged beside DIR, the rename into it crossed devices: "Invalid cross-device link", always.
  const auto r = run_cli({"report", "--only", "rng", "--out", m.dir.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, Not(HasSubstr(".tmp-")));
  EXPECT_TRUE(fs::exists(m.dir / "index.html"));
  const std::size_t n = entries(m.dir);  // the report's files, no staging directory left
  EXPECT_EQ(entries(d.path()), 1u);      // only mnt
  // A failed command leaves nothing new there either.
  write_text(d / "stiff.yaml", "friction:\n  rho0_a_N_m: 1e9\n");
  expect_error({"stickslip", "simulate", "--params", (d / "stiff.yaml").string(), "--out", m.dir.string()}, 3,
               "rho0_a_N_m");
  EXPECT_EQ(entries(m.dir), n);
}

TEST(InputsHardening, MessagesNameWhatTheUserGave) {
  TempDir d;
  auto err = expect_error({"design", "ballscrew", "--diameter", "0.006", "--lead", "1e20", "--mu", "0.1"}, 3,
                          "--lead");
  EXPECT_THAT(err, Not(HasSubstr("lead_angle_rad")));
  err = expect_error({"tweezers", "virtual-cube", "--rate", "15", "--json"}, 3, "--rate");
  EXPECT_THAT(err, Not(HasSubstr("zero_Hz:")));
  // A name beyond the file system's limit is named as such, not as an unwritable parent ...
  err = expect_error({"report", "--only", "rng", "--out", (d / std::string(300, 'a')).string()}, 3,
                     "300 characters long (the limit is 255)");
  EXPECT_THAT(err, Not(HasSubstr("not writable")));
  // ... and a name near the limit works: its staging directory's name must fit too.
  const auto r = run_cli({"report", "--only", "rng", "--out", (d / std::string(250, 'b')).string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d / std::string(250, 'b') / "index.html"));
}

TEST(InputsHardening, AbsurdRunConfigurationsAreRefusedBeforeTheSession) {
  TempDir d;
  // Both ran the whole session until it timed out (exit 4, ~20 s each).
  write_text(d / "home.yaml", "stage:\n  home_x_m: 1\n");
  expect_error({"run", "--config", (d / "home.yaml").string(), "--out", (d / "s").string()}, 3,
               "stage.home_x_m");
  write_text(d / "gravity.yaml", "world:\n  gravity_m_s2: 1e308\n");
  expect_error({"run", "--config", (d / "gravity.yaml").string(), "--out", (d / "s").string()}, 3,
               "world.gravity_m_s2");
  // The axes' own stroke counts: a 1 mm stroke cannot reach the 2 mm target.
  write_text(d / "axis.yaml", "slider:\n  stroke_m: 0.001\n");
  write_text(d / "short.yaml", "stickslip_params_file: axis.yaml\n");
  expect_error({"run", "--config", (d / "short.yaml").string(), "--print-config"}, 3, "world.target_x_m");
  EXPECT_FALSE(fs::exists(d / "s"));
}

TEST(InputsHardening, ASignalWhileARunWritesItsOutputsExits130WithThemWhole) {
  TempDir d;
  const auto s = test::spawn_cli({"run", "--out", (d / "s").string()}, d / "run");
  // The session ends, then its recording and report are written into the staging directory
  // (~1 s): the signal comes as the first file appears there.
  const bool writing = test::eventually(
      [&] {
        for (const auto& e : fs::directory_iterator(d.path())) {
          if (e.path().filename().string().rfind(".s.tmp-", 0) == 0 && !fs::is_empty(e.path())) return true;
        }
        return false;
      },
      std::chrono::seconds(120));
  ASSERT_TRUE(writing);
  ::kill(s.pid, SIGINT);
  EXPECT_EQ(test::wait_process(s.pid, std::chrono::seconds(60)), 130);  // it exited 0
  const auto err = test::read_text(s.err);
  EXPECT_EQ(line_count(err), 1u) << err;
  EXPECT_THAT(err, HasSubstr("SIGINT"));
  // All of it, whole: the session had finished, so nothing is marked as interrupted.
  for (const char* f : {"recording.csv", "recording.mcap", "index.html"})
    EXPECT_TRUE(fs::exists(d / "s" / f)) << f;
  EXPECT_THAT(test::read_text(d / "s" / "recording.csv").substr(0, 200), Not(HasSubstr("interrupted")));
  EXPECT_EQ(entries(d.path()), 3u);  // s, run.out, run.err: no staging directory
}

}  // namespace
}  // namespace inputs_hardening_test
}  // namespace mc
