// A bad --params file through real commands of every group that takes one: exit 3 and one
// line on stderr naming the file and line (parse errors) or the parameter (validation).

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"

namespace mc {
namespace {

using test::line_count;
using test::run_cli;
using ::testing::HasSubstr;

struct Command {
  std::vector<std::string> args;  ///< without --params
  std::string section;            ///< a map of parameters the command reads
  std::string number_key;         ///< a numeric key inside it
  std::string out_of_range;       ///< a YAML value of number_key that validation rejects
  std::string named;              ///< how the validation error names the key
};

const std::vector<Command>& commands() {
  static const std::vector<Command> c = {
      {{"stickslip", "simulate", "--duration", "1e-4"}, "integrator", "dt_s", "1.0e-3", "integrator.dt_s"},
      {{"control", "velocity"}, "velocity", "sawtooth_frequency_Hz", "-1", "velocity.sawtooth_frequency_Hz"},
      {{"haptics", "tweezers"}, "trap", "trap_stiffness_N_per_m", "-1.0e-5", "trap.trap_stiffness_N_per_m"},
      {{"tweezers", "identify"}, "model", "lead_m", "-1", "lead_m"},
  };
  return c;
}

struct Run {
  int exit_code;
  std::string err;
};

Run run_with(const test::TempDir& dir, const Command& c, const std::string& yaml) {
  const auto file = dir / "p.yaml";
  test::write_text(file, yaml);
  std::vector<std::string> args = c.args;
  args.insert(args.end(), {"--json", "--params", file.string()});
  const auto r = run_cli(args);
  EXPECT_EQ(r.out, "") << c.args[0];
  return {r.exit_code, r.err};
}

void expect_one_line_3(const Run& r, const std::vector<std::string>& mentions, const std::string& what) {
  EXPECT_EQ(r.exit_code, 3) << what << ": " << r.err;
  EXPECT_EQ(line_count(r.err), 1u) << what << ": " << r.err;
  EXPECT_THAT(r.err, HasSubstr("microcobot: error:")) << what;
  for (const auto& m : mentions) EXPECT_THAT(r.err, HasSubstr(m)) << what;
}

TEST(ParamsCli, MalformedYamlNamesTheFileAndLine) {
  test::TempDir dir;
  for (const auto& c : commands()) {
    const auto r = run_with(dir, c, c.section + ":\n  " + c.number_key + ": [1, 2\n");
    expect_one_line_3(r, {(dir / "p.yaml").string() + ":", "malformed YAML"}, c.args[0]);
  }
}

TEST(ParamsCli, UnknownKeyNamesTheFileLineAndKey) {
  test::TempDir dir;
  for (const auto& c : commands()) {
    const auto r = run_with(dir, c, c.section + ":\n  no_such_key_m: 1\n");
    expect_one_line_3(r, {(dir / "p.yaml").string() + ":2:", "unknown key '" + c.section + ".no_such_key_m'"},
                      c.args[0]);
    const auto top = run_with(dir, c, "\nbogus_section: 1\n");
    expect_one_line_3(top, {(dir / "p.yaml").string() + ":2:", "unknown key 'bogus_section'"}, c.args[0]);
  }
}

TEST(ParamsCli, WrongTypeNamesTheFileLineAndKey) {
  test::TempDir dir;
  for (const auto& c : commands()) {
    const auto r = run_with(dir, c, c.section + ":\n\n  " + c.number_key + ": fast\n");
    expect_one_line_3(r, {(dir / "p.yaml").string() + ":3:", c.number_key}, c.args[0]);
    // A map where a number belongs, and a scalar where a map belongs.
    const auto map = run_with(dir, c, c.section + ":\n  " + c.number_key + ":\n    x: 1\n");
    expect_one_line_3(map, {(dir / "p.yaml").string() + ":", c.number_key}, c.args[0]);
    const auto scalar = run_with(dir, c, c.section + ": 3\n");
    expect_one_line_3(scalar, {(dir / "p.yaml").string() + ":1:", c.section}, c.args[0]);
  }
}

TEST(ParamsCli, OutOfRangeValueNamesTheParameter) {
  test::TempDir dir;
  for (const auto& c : commands()) {
    const auto r = run_with(dir, c, c.section + ":\n  " + c.number_key + ": " + c.out_of_range + "\n");
    expect_one_line_3(r, {"invalid parameter", c.named}, c.args[0]);
  }
}

TEST(ParamsCli, MissingFileNamesIt) {
  test::TempDir dir;
  for (const auto& c : commands()) {
    std::vector<std::string> args = c.args;
    args.insert(args.end(), {"--params", (dir / "absent.yaml").string()});
    const auto r = run_cli(args);
    expect_one_line_3({r.exit_code, r.err}, {(dir / "absent.yaml").string(), "cannot open file"}, c.args[0]);
  }
}

}  // namespace
}  // namespace mc
