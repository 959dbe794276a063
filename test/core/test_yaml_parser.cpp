/// The libyaml front end of the scenario loader: the trees it builds are those of yaml-cpp's own
/// YAML::Load(), node for node and tag for tag, and what it refuses names "(file)".

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/ParameterError.hpp"
#include "projection_collision_avoidance/ScenarioLoader.hpp"

#include "TestScenarios.hpp"
#include "YamlParser.hpp"

namespace projection_collision_avoidance {
namespace {

using detail::parseYaml;

/// Empty when the trees are equal (type, tag, scalar text, sizes, keys in order), else where
/// and how they differ.
// NOLINTNEXTLINE(misc-no-recursion)
std::string difference(const YAML::Node& a, const YAML::Node& b, const std::string& path) {
  if (a.Type() != b.Type()) {
    return path + ": type " + std::to_string(a.Type()) + " against " + std::to_string(b.Type());
  }
  if (a.IsScalar()) {
    if (a.Scalar() != b.Scalar() || a.Tag() != b.Tag()) {
      return path + ": '" + a.Scalar() + "' " + a.Tag() + " against '" + b.Scalar() + "' " +
             b.Tag();
    }
    return "";
  }
  if (a.size() != b.size()) {
    return path + ": " + std::to_string(a.size()) + " entries against " + std::to_string(b.size());
  }
  if (a.IsSequence()) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string d = difference(a[i], b[i], path + "." + std::to_string(i));
      if (!d.empty()) {
        return d;
      }
    }
  }
  if (a.IsMap()) {
    auto ia = a.begin();
    auto ib = b.begin();
    for (; ia != a.end(); ++ia, ++ib) {
      std::string d = difference(ia->first, ib->first, path + " key");
      if (d.empty()) {
        d = difference(ia->second, ib->second, path + "." + ia->first.as<std::string>("?"));
      }
      if (!d.empty()) {
        return d;
      }
    }
  }
  return "";
}

std::string fileText(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(YamlParser, BuildsYamlCppsTreeForEveryScenarioFile) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SCENARIO_DIR)) {
    if (entry.path().extension() != ".yaml") {
      continue;
    }
    const std::string text = fileText(entry.path().string());
    EXPECT_EQ(difference(parseYaml(text), YAML::Load(text), "(root)"), "") << entry.path();
    ++files;
  }
  EXPECT_GE(files, 4);
}

TEST(YamlParser, BuildsYamlCppsTreeForEachKindOfNode) {
  const std::vector<std::string> texts = {
      "a: 1\nb: [1, 2.5, -3e2]\nc: {d: x, e: [y, {f: z}]}\n",
      "plain: 1\nsingle: '1'\ndouble: \"1\"\ntagged: !!str 1\nfloat: !!float 2\nlocal: !mine 3\n",
      "nulls: [~, null, Null, NULL, '', '~']\nempty:\nafter: 1\n",
      "literal: |\n  two\n  lines\nfolded: >\n  one\n  line\n",
      "base: &b [1, 2]\ncopy: *b\nmap: &m {k: v}\nmaps: [*m, *m]\n",
      "- a\n- - b\n  - c\n- {d: e}\n",
      "# only a comment\n",
      "",
      "first: 1\n---\nsecond: 2\n",
      "%YAML 1.1\n---\nk: v\n...\n",
      "inf: .inf\nnan: .nan\nhex: 0x1F\nbool: [true, False, yes]\n",
      "? [complex, key]\n: value\n",
  };
  for (const std::string& text : texts) {
    EXPECT_EQ(difference(parseYaml(text), YAML::Load(text), "(root)"), "") << text;
  }
}

TEST(YamlParser, AnAliasSharesItsAnchorsNode) {
  const YAML::Node root = parseYaml("a: &x [1]\nb: *x\n");
  EXPECT_TRUE(root["a"].is(root["b"]));
}

/// Expects @p text to be refused with key "(file)" and a message containing @p what.
void expectRefused(const std::string& text, const std::string& what) {
  try {
    parseYaml(text);
    ADD_FAILURE() << "accepted " << text;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "(file)") << error.what();
    EXPECT_NE(std::string(error.what()).find(what), std::string::npos) << error.what();
  }
}

TEST(YamlParser, RefusesWhatIsNotYaml) {
  expectRefused("model: [unclosed", "line 2");
  expectRefused("a: b: c\n", "line 1, column 5");
  expectRefused("a: 1\n  b: 2\n", "not valid YAML");
  expectRefused("a: *nowhere\n", "alias *nowhere");
  expectRefused("a:\n  b: 1\n  b: 2\n", "'b' appears twice");
  expectRefused("\t- tab\n", "not valid YAML");
}

TEST(YamlParser, TheScenarioLoaderRefusesADuplicatedKeyAndABadOverride) {
  const std::string text = fileText(testing::scenarioPath("paper_run2.yaml"));
  EXPECT_THROW(parseScenario(text + "simulation:\n  duration: 1.0\n"), ParameterError);
  try {
    parseScenario(text, {"controller.alpha=[0.2"});
    ADD_FAILURE() << "accepted an override that is not YAML";
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "controller.alpha") << error.what();
    EXPECT_NE(std::string(error.what()).find("not valid YAML"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace projection_collision_avoidance
