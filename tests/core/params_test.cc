#include "microcobot/core/params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;

struct ModeParams {
  double frequency_Hz = 100.0;
  double damping = 0.05;
  template <class V>
  void visit(V& v) {
    v("frequency_Hz", frequency_Hz);
    v("damping", damping);
  }
  void validate() const {
    require_positive(frequency_Hz, "mode.frequency_Hz");
    require_in_range(damping, 0.0, 1.0, "mode.damping");
  }
};

struct DemoParams {
  double mass_kg = 1e-3;
  int operators = 35;
  bool enabled = true;
  std::string name = "axis";
  std::vector<double> weights{1.0, 2.0};
  std::vector<std::vector<double>> table{{1.0, 2.0}, {3.0, 4.0}};
  ModeParams mode;
  std::vector<ModeParams> modes{ModeParams{}, ModeParams{200.0, 0.1}};
  template <class V>
  void visit(V& v) {
    v("mass_kg", mass_kg);
    v("operators", operators);
    v("enabled", enabled);
    v("name", name);
    v("weights", weights);
    v("table", table);
    v("mode", mode);
    v("modes", modes);
  }
  void validate() const {
    require_positive(mass_kg, "mass_kg");
    mode.validate();
    for (const ModeParams& m : modes) m.validate();
  }
};

TEST(Params, DefaultsSurviveAnEmptyDocumentAndKeysOverride) {
  const auto p = params_from_yaml_text<DemoParams>("mass_kg: 2.5e-3\nmode: {damping: 0.2}\n");
  EXPECT_DOUBLE_EQ(p.mass_kg, 2.5e-3);
  EXPECT_DOUBLE_EQ(p.mode.damping, 0.2);
  EXPECT_DOUBLE_EQ(p.mode.frequency_Hz, 100.0);  // untouched default
  EXPECT_EQ(p.operators, 35);
  const auto empty = params_from_yaml_text<DemoParams>("");
  EXPECT_DOUBLE_EQ(empty.mass_kg, 1e-3);
}

TEST(Params, JsonRoundTripsThroughTheLoader) {
  DemoParams p;
  p.mass_kg = 0.1234567890123;
  p.weights = {0.5, 0.25, 1e-9};
  p.table = {{1, 2, 3}};
  p.name = "z axis";
  const auto json = params_to_json(p);
  const auto back = params_from_yaml_text<DemoParams>(json.dump());
  EXPECT_EQ(params_to_json(back), json);
  const auto from_yaml = params_from_yaml_text<DemoParams>(params_to_yaml(p));
  EXPECT_EQ(params_to_json(from_yaml), json);
}

TEST(Params, UnknownKeyIsRejectedWithItsPathAndLine) {
  try {
    params_from_yaml_text<DemoParams>("mass_kg: 1\nmode:\n  frequency_Hz: 5\n  dampnig: 0.1\n");
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown key 'mode.dampnig'"));
    EXPECT_EQ(e.line(), 4u);
  }
}

TEST(Params, WrongTypesAreRejectedNamingTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"mass_kg: heavy", "'mass_kg' must be a finite number"},
      {"operators: 3.5", "'operators' must be an integer"},
      {"enabled: yes-please", "'enabled' must be true or false"},
      {"weights: 3", "'weights' must be a list of numbers"},
      {"weights: [1, x]", "'weights[1]' must be a finite number"},
      {"mode: 7", "'mode' must be a map"},
      {"table: [[1, 2], 3]", "'table[1]' must be a list"},
      {"mass_kg: .nan", "'mass_kg' must be a finite number"},
  };
  for (const auto& [text, message] : cases) {
    try {
      params_from_yaml_text<DemoParams>(text);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr(message)) << text;
      EXPECT_THAT(e.what(), HasSubstr("<yaml>:1:")) << text;
      EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput);
    }
  }
}

TEST(Params, MalformedYamlNamesTheLine) {
  try {
    params_from_yaml_text<DemoParams>("mass_kg: 1\nmode: {damping: 0.1\n");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("malformed YAML"));
    EXPECT_GT(e.line(), 0u);
  }
}

TEST(Params, ValidateRunsAfterLoadingAndNamesTheConstraint) {
  try {
    params_from_yaml_text<DemoParams>("mode: {damping: 1.5}");
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_EQ(e.field(), "mode.damping");
    EXPECT_THAT(e.what(), HasSubstr("must be in [0, 1] (got 1.5)"));
  }
}

TEST(Params, AListOfStructsReplacesTheDefaultListElementByElementOverTheirDefaults) {
  const auto p =
      params_from_yaml_text<DemoParams>("modes:\n  - {damping: 0.3}\n  - {frequency_Hz: 7}\n  - {}\n");
  ASSERT_EQ(p.modes.size(), 3u);
  EXPECT_DOUBLE_EQ(p.modes[0].damping, 0.3);
  EXPECT_DOUBLE_EQ(p.modes[0].frequency_Hz, 100.0);  // the element's default, not the old list's
  EXPECT_DOUBLE_EQ(p.modes[1].frequency_Hz, 7.0);
  EXPECT_DOUBLE_EQ(p.modes[2].damping, 0.05);
  EXPECT_EQ(params_to_json(p)["modes"].size(), 3u);
  EXPECT_EQ(params_to_json(params_from_yaml_text<DemoParams>(params_to_yaml(p))), params_to_json(p));
  const auto untouched = params_from_yaml_text<DemoParams>("mass_kg: 1\n");
  EXPECT_EQ(untouched.modes.size(), 2u);
  const auto expect_refusal = [](const std::string& yaml, const std::string& what, std::size_t line) {
    try {
      params_from_yaml_text<DemoParams>(yaml);
      FAIL() << "expected InvalidInput for " << yaml;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr(what));
      EXPECT_EQ(e.line(), line) << e.what();
    }
  };
  expect_refusal("modes:\n  - {damping: 0.3}\n  - {dampnig: 0.1}\n", "unknown key 'modes[1].dampnig'", 3u);
  expect_refusal("modes: 3\n", "'modes' must be a list of maps", 1u);
  expect_refusal("modes:\n  - 3\n", "'modes[0]' must be a map", 2u);
  EXPECT_THROW(params_from_yaml_text<DemoParams>("modes:\n  - {damping: 2}\n"), InvalidParams);
}

TEST(Params, MissingFileIsInvalidInput) {
  test::TempDir dir;
  EXPECT_THROW(load_params<DemoParams>(dir / "nope.yaml"), InvalidInput);
  test::write_text(dir / "p.yaml", "# comment\nmass_kg: 3\n");
  EXPECT_DOUBLE_EQ(load_params<DemoParams>(dir / "p.yaml").mass_kg, 3.0);
}

}  // namespace
}  // namespace mc
