/// The libyaml front end of the scenario loader: the trees it builds are those of yaml-cpp's own
/// YAML::Load(), node for node and tag for tag, and what it refuses names "(file)". Its limits
/// (size, depth, nodes with aliases expanded) and its cancellation.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"
#include "projection_collision_avoidance/scenario/ScenarioLoader.hpp"

#include "TestScenarios.hpp"
#include "YamlParser.hpp"

namespace projection_collision_avoidance {
namespace {

using detail::kCancelPollEvents;
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

/// The message of the ParameterError that parsing @p text ends with ("" and a failure if none).
std::string refusal(const std::string& text) {
  try {
    parseYaml(text);
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.key(), "(file)") << error.what();
    return error.what();
  }
  ADD_FAILURE() << "accepted " << text.substr(0, 80) << "...";
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// @p depth flow lists nested in one another: "[[[]]]".
std::string nestedLists(std::size_t depth) {
  return std::string(depth, '[') + std::string(depth, ']');
}

/// A flow list of @p items plain scalars: items + 1 nodes on line 1, item i at column 2 + 2 i.
std::string flatList(std::size_t items) {
  std::string text = "[";
  for (std::size_t i = 0; i < items; ++i) {
    text += i == 0 ? "1" : ",1";
  }
  return text + "]";
}

TEST(YamlParserLimits, RefusesTextOverTheSizeLimit) {
  std::string text = "a: 1\n#";  // a comment pads the document to the limit
  text.resize(kMaxScenarioBytes, 'x');
  EXPECT_EQ(parseYaml(text)["a"].as<int>(), 1);
  text += 'x';
  const std::string message = refusal(text);
  EXPECT_TRUE(contains(message, "size limit")) << message;
  EXPECT_TRUE(contains(message, "(" + std::to_string(kMaxScenarioBytes) + " bytes)")) << message;
  EXPECT_TRUE(contains(message, "has " + std::to_string(text.size()) + " bytes")) << message;
}

TEST(YamlParserLimits, RefusesNestingOverTheDepthLimit) {
  EXPECT_TRUE(parseYaml(nestedLists(kMaxScenarioDepth)).IsSequence());
  std::string message = refusal(nestedLists(kMaxScenarioDepth + 1));
  EXPECT_TRUE(contains(message, "depth limit")) << message;
  EXPECT_TRUE(contains(message, "(" + std::to_string(kMaxScenarioDepth) + " lists and maps)"))
      << message;
  EXPECT_TRUE(contains(message, "line 1, column " + std::to_string(kMaxScenarioDepth + 1)))
      << message;
  // Block maps count as lists do (the root map and controller's are two levels); the message
  // gives the path to the entry.
  message = refusal("controller:\n  extra: " + nestedLists(kMaxScenarioDepth - 1) + "\n");
  EXPECT_TRUE(contains(message, "line 2, column " + std::to_string(kMaxScenarioDepth + 8)))
      << message;
  EXPECT_TRUE(contains(message, "in controller.extra.0.0")) << message;
  // A file of nothing but opening brackets is refused at the limit, not read to its end.
  message = refusal(std::string(kMaxScenarioBytes, '['));
  EXPECT_TRUE(contains(message, "depth limit")) << message;
}

TEST(YamlParserLimits, RefusesTreesOverTheNodeLimit) {
  EXPECT_EQ(parseYaml(flatList(kMaxScenarioNodes - 1)).size(), kMaxScenarioNodes - 1);
  const std::string message = refusal(flatList(kMaxScenarioNodes));
  EXPECT_TRUE(contains(message, "node limit")) << message;
  EXPECT_TRUE(contains(message, "(" + std::to_string(kMaxScenarioNodes) + " nodes")) << message;
  EXPECT_TRUE(contains(message, "line 1, column " + std::to_string(2 * kMaxScenarioNodes)))
      << message;
  EXPECT_TRUE(contains(message, "in " + std::to_string(kMaxScenarioNodes - 1))) << message;
}

TEST(YamlParserLimits, CountsAnAliasAsTheNodesItRepeats) {
  // a: 1000 nodes; b: k aliases of a. In all 1 (root) + 1 + 1000 + 1 + 1 + 1000 k nodes.
  const std::string anchor = "a: &a " + flatList(999) + "\n";
  const std::size_t most = (kMaxScenarioNodes - 1004) / 1000;
  const auto aliases = [&](std::size_t k) {
    std::string text = anchor + "b: [";
    for (std::size_t i = 0; i < k; ++i) {
      text += i == 0 ? "*a" : ", *a";
    }
    return text + "]\n";
  };
  EXPECT_EQ(parseYaml(aliases(most))["b"].size(), most);
  const std::string message = refusal(aliases(most + 1));
  EXPECT_TRUE(contains(message, "node limit")) << message;
  EXPECT_TRUE(contains(message, "in b." + std::to_string(most))) << message;
}

TEST(YamlParserLimits, RefusesAnAliasBomb) {
  // Line i + 1 holds l<i>: ten aliases of l<i-1>, 10^10 nodes expanded by l9. It is refused
  // on the first line that takes the expanded count over the limit.
  std::string text = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  std::size_t size = 11;           // nodes of l<i>
  std::size_t total = 1 + 1 + 11;  // the root map, the key l0 and l0
  std::size_t refused_line = 0;
  for (int i = 1; i <= 9; ++i) {
    const std::string previous = "*l" + std::to_string(i - 1);
    text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [" + previous;
    for (int k = 1; k < 10; ++k) {
      text += ", " + previous;
    }
    text += "]\n";
    size = 1 + 10 * size;
    total += 1 + size;
    if (refused_line == 0 && total > kMaxScenarioNodes) {
      refused_line = static_cast<std::size_t>(i) + 1;
    }
  }
  ASSERT_NE(refused_line, 0U);
  const std::string message = refusal(text);
  EXPECT_TRUE(contains(message, "node limit")) << message;
  EXPECT_TRUE(contains(message, "line " + std::to_string(refused_line) + ",")) << message;
  // An alias inside the collection it names would repeat without end.
  EXPECT_TRUE(contains(refusal("a: &a [1, *a]\n"), "lies inside the collection it repeats"));
}

TEST(YamlParserLimits, StopsWhenCancelled) {
  const std::size_t items = 10 * kCancelPollEvents;
  const std::string text = flatList(items);
  std::size_t polls = 0;
  const auto never = [&polls] {
    ++polls;
    return false;
  };
  EXPECT_EQ(parseYaml(text, never).size(), items);
  EXPECT_GE(polls, items / kCancelPollEvents);  // one event per item, and a few more
  polls = 0;
  const auto third = [&polls] { return ++polls == 3; };
  try {
    parseYaml(text, third);
    ADD_FAILURE() << "not cancelled";
  } catch (const ScenarioLoadCancelled& error) {
    EXPECT_EQ(polls, 3U);
    EXPECT_TRUE(contains(error.what(), "loading cancelled at line 1, column ")) << error.what();
  }
  // Before the first event, and through the loader as the same exception (not a ParameterError).
  EXPECT_THROW(parseYaml("a: 1\n", [] { return true; }), ScenarioLoadCancelled);
  ScenarioLoadOptions options;
  options.cancelled = [] { return true; };
  EXPECT_THROW(loadScenarioFile(testing::scenarioPath("paper_run2.yaml"), {}, options),
               ScenarioLoadCancelled);
  options.cancelled = [] { return false; };
  EXPECT_NO_THROW(loadScenarioFile(testing::scenarioPath("paper_run2.yaml"), {}, options));
}

}  // namespace
}  // namespace projection_collision_avoidance
