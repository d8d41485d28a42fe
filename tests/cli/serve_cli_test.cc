// `microcobot serve`'s scenes from the command line: a built-in name or a YAML file; a bad file
// is refused before anything starts, with one line naming the key.
#include <gtest/gtest.h>

#include "support/test_support.h"

namespace mc {
namespace {

using test::run_cli;

std::size_t lines(const std::string& s) { return test::line_count(s); }

TEST(ServeCli, TheSceneFileOfTheRepositoryAndTheBuiltInScenesStart) {
  test::TempDir dir;
  for (const std::string scene : {"pick-place", "pin-in-hole", MC_SOURCE_DIR "/scenes/pin-in-hole.yaml"}) {
    const auto r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", dir.path().string(), "--scene",
                            scene, "--duration", "0.3"});
    EXPECT_EQ(r.exit_code, 0) << scene << ": " << r.err;
    EXPECT_EQ(r.out.rfind("http://127.0.0.1:", 0), 0u) << "the first line is the console's URL: " << r.out;
  }
}

TEST(ServeCli, TheVendorTwinsPrintTheirPortsAndABadEmulateIsOneLine) {
  test::TempDir dir;
  auto r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", dir.path().string(), "--emulate",
                    "gcs2=127.0.0.1:0", "--emulate", "anc300=127.0.0.1:0", "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\nemulate gcs2 127.0.0.1:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nemulate anc300 127.0.0.1:"), std::string::npos) << r.out;
  for (const std::string bad : {"smaract", "gcs2=127.0.0.1", "anc300=127.0.0.1:99999"}) {
    r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", dir.path().string(), "--emulate", bad,
                 "--duration", "0.3"});
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  }
  // A port that cannot be bound (an address of no interface here): invalid input, named.
  r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", dir.path().string(), "--token",
               "0123456789abcdef", "--emulate", "gcs2=192.0.2.1:0", "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("--emulate gcs2: cannot listen on 192.0.2.1:0"), std::string::npos) << r.err;
}

TEST(ServeCli, ABadSceneIsRefusedWithOneLineNamingTheKey) {
  test::TempDir dir;
  const struct {
    std::string yaml, expected;
  } cases[] = {
      {"part_side_m: 200.0e-6\nhole_side_m: 150.0e-6\nhole_depth_m: 100.0e-6\n", "hole_side_m"},
      {"part_side_m: 200.0e-6\npart_height_m: 300.0e-6\nhole_side_m: 220.0e-6\nhole_depth_m: 400.0e-6\n",
       "hole_depth_m"},
      {"part_sides_m: 1.0e-4\n", "part_sides_m"},
      {"part_side_m: .nan\n", "part_side_m"},
  };
  for (const auto& c : cases) {
    test::write_text(dir / "scene.yaml", c.yaml);
    const auto r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", (dir / "out").string(), "--scene",
                            (dir / "scene.yaml").string(), "--duration", "0.3"});
    EXPECT_EQ(r.exit_code, 3) << c.yaml << r.err;  // invalid input (docs/cli.md)
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "nothing served";
  }
}

// A mistyped scene lists the built-in ones; an --out that cannot be created is one
// line naming it (exit 3, not an internal error); on every interface the URL to open is loopback's.
TEST(ServeCli, AMistypedSceneOrAnUncreatableOutIsOneHelpfulLine) {
  test::TempDir dir;
  auto r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", dir.path().string(), "--scene", "pin-in-hol",
                    "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  for (const char* name : {"pin-in-hol", "pick-place", "pin-in-hole", "optical-trap"})
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  test::write_text(dir / "a-file", "x");
  for (const std::string& out : {std::string("/proc/nope"), (dir / "a-file" / "sub").string()}) {
    r = run_cli({"serve", "--listen", "127.0.0.1:0", "--out", out, "--duration", "0.3"});
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("cannot create --out " + out), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
  r = run_cli({"serve", "--listen", "0.0.0.0:0", "--out", dir.path().string(), "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("http://127.0.0.1:", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("?token="), std::string::npos) << "off loopback a token is needed: " << r.out;
}

TEST(ServeCli, AnUnknownDriverInTheConfigurationIsOneLineListingTheKnownOnes) {
  // The program registers the vendor drivers beside the simulation (docs/hardware.md).
  test::TempDir dir;
  test::write_text(dir / "bench.yaml", "devices: {driver: smaract, connection: \"usb:0\"}\n");
  for (const std::string command : {"serve", "run"}) {
    const auto r =
        run_cli({command, "--config", (dir / "bench.yaml").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.exit_code, 3) << command << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("devices.driver: 'smaract' is not a registered driver (known: simulated, anc300, "
                         "pi-gcs2, smaract-mcs2)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out, "") << "nothing served or run";
  }
}

TEST(ServeCli, ABadRecordVideoIsAUsageErrorNamingTheFlagAndWhatWasGiven) {
  const auto r = run_cli({"serve", "--listen", "127.0.0.1:0", "--duration", "0.2", "--record-video", "mp4"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--record-video: 'mp4' must be h264, jpeg or off"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "") << "nothing served";
}

TEST(ServeCli, TheLinkFlagsAreUsageErrorsNamingTheFlag) {
  const struct {
    std::vector<std::string> args;
    std::string flag;
  } cases[] = {
      {{"--role", "both"}, "--role"},
      {{"--role", "slave", "--domain", "231"}, "--domain"},
      {{"--link-delay", "0.05"}, "--link-delay"},  // only between two processes
      {{"--role", "master", "--link-delay", "0.01", "--link-jitter", "0.02"}, "--link-jitter"},
      {{"--role", "master", "--link-loss", "1"}, "--link-loss"},
      {{"--role", "slave", "--link-delay", "nan"}, "--link-delay"},
      {{"--interface", "eth0"}, "--interface"},  // a link's, as the emulator's flags
      {{"--role", "slave", "--interface", "eth0\"/><x"}, "--interface"},
      {{"--role", "master", "--peer", "10.0.0.2", "--peer", "a b"}, "--peer"},
      {{"--passivity", "off"}, "--passivity"},  // the ports are the link's
      {{"--role", "slave", "--passivity", "yes"}, "--passivity"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {"serve", "--listen", "127.0.0.1:0", "--duration", "0.2"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << c.flag << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(c.flag), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "nothing served";
  }
}

}  // namespace
}  // namespace mc
