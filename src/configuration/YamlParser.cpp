#include "YamlParser.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <ios>
#include <map>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <yaml.h>

#include "projection_collision_avoidance/configuration/ConfigurationLoader.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance::detail {
namespace {

/// Path elements shown in a message; a deeper path ends in "...".
constexpr std::size_t kPathElementsShown = 8;

/// Bytes read from a scenario file at a time.
constexpr std::size_t kReadChunkBytes = 16384;

std::string tooLarge(const std::string& path, const std::string& size) {
  return "'" + path + "' has " + size + " bytes, over the size limit of a scenario (" +
         std::to_string(kMaxScenarioBytes) + " bytes)";
}

std::string at(const yaml_mark_t& mark) {
  return "line " + std::to_string(mark.line + 1) + ", column " + std::to_string(mark.column + 1);
}

/// Owns a libyaml parser reading @p text.
class EventParser {
 public:
  explicit EventParser(const std::string& text) {
    if (yaml_parser_initialize(&parser_) == 0) {
      throw ParameterError("(file)", "cannot start the YAML parser (out of memory)");
    }
    // libyaml reads the bytes and never writes them.
    yaml_parser_set_input_string(&parser_, reinterpret_cast<const unsigned char*>(text.data()),
                                 text.size());
  }
  ~EventParser() { yaml_parser_delete(&parser_); }
  EventParser(const EventParser&) = delete;
  EventParser& operator=(const EventParser&) = delete;
  EventParser(EventParser&&) = delete;
  EventParser& operator=(EventParser&&) = delete;

  /// The next event into @p event (which the caller deletes).
  void next(yaml_event_t* event) {
    if (yaml_parser_parse(&parser_, event) == 0) {
      std::string why = "not valid YAML: ";
      why += parser_.problem != nullptr ? parser_.problem : "syntax error";
      if (parser_.context != nullptr) {
        why = why + " " + parser_.context;
      }
      throw ParameterError("(file)", why + " at " + at(parser_.problem_mark));
    }
  }

  /// Where the parser has read to.
  const yaml_mark_t& mark() const { return parser_.mark; }

 private:
  yaml_parser_t parser_{};
};

/// Deletes an event when it goes out of scope.
class Event {
 public:
  Event() = default;
  ~Event() { yaml_event_delete(&event_); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  Event(Event&&) = delete;
  Event& operator=(Event&&) = delete;
  yaml_event_t* get() { return &event_; }
  const yaml_event_t& operator*() const { return event_; }

 private:
  yaml_event_t event_{};
};

std::string text(const yaml_char_t* characters) {
  return characters == nullptr ? std::string() : reinterpret_cast<const char*>(characters);
}

bool isNullText(const std::string& value) {
  return value.empty() || value == "~" || value == "null" || value == "Null" || value == "NULL";
}

YAML::Node scalarNode(const yaml_event_t& event) {
  const auto& scalar = event.data.scalar;
  std::string value(reinterpret_cast<const char*>(scalar.value), scalar.length);
  const bool plain = scalar.style == YAML_PLAIN_SCALAR_STYLE;
  if (plain && scalar.tag == nullptr && isNullText(value)) {
    return YAML::Node(YAML::NodeType::Null);
  }
  YAML::Node node(std::move(value));
  node.SetTag(scalar.tag != nullptr ? text(scalar.tag) : (plain ? "?" : "!"));
  return node;
}

/// A collection being read: its node, and for a map the key waiting for its value.
struct OpenCollection {
  YAML::Node node;
  bool is_map = false;
  bool have_key = false;
  YAML::Node key;
  std::set<std::string> scalar_keys;  // to refuse a key that appears twice
  std::size_t nodes = 1;              // in its tree so far, itself included, aliases expanded
  std::string anchor;                 // "" if it has none
};

/// An anchored node and the nodes of its tree (aliases expanded); open while its collection is
/// still being read.
struct Anchor {
  YAML::Node node;
  std::size_t nodes = 1;
  bool open = false;
};

/// Builds the tree from the events, counting nodes and depth as they arrive.
class TreeBuilder {
 public:
  /// The dotted path of the entry being read ("(root)" at the top), for messages.
  std::string where() const {
    std::string path;
    std::size_t shown = 0;
    for (const OpenCollection& collection : open_) {
      if (shown == kPathElementsShown) {
        return path + "...";
      }
      std::string element;
      if (!collection.is_map) {
        element = std::to_string(collection.node.size());
      } else if (collection.have_key && collection.key.IsScalar()) {
        element = collection.key.Scalar();
      } else {
        continue;  // reading a key: the path ends at this map
      }
      path += (path.empty() ? "" : ".") + element;
      ++shown;
    }
    return path.empty() ? "(root)" : path;
  }

  /// Counts @p count more nodes read at @p mark.
  void count(std::size_t count, const yaml_mark_t& mark) {
    total_ += count;
    if (total_ > kMaxScenarioNodes) {
      throw ParameterError("(file)", "over the node limit of a scenario (" +
                                         std::to_string(kMaxScenarioNodes) +
                                         " nodes, an alias counting as the nodes it repeats) at " +
                                         at(mark) + ", in " + where());
    }
  }

  void scalar(const yaml_event_t& e) {
    count(1, e.start_mark);
    const YAML::Node node = scalarNode(e);
    remember(e.data.scalar.anchor, node, 1, false);
    attach(node, 1, e.start_mark);
  }

  void alias(const yaml_event_t& e) {
    const std::string name = text(e.data.alias.anchor);
    const auto found = anchors_.find(name);
    if (found == anchors_.end()) {
      throw ParameterError("(file)", "not valid YAML: the alias *" + name +
                                         " names no anchor before it (line " +
                                         std::to_string(e.start_mark.line + 1) + ")");
    }
    if (found->second.open) {
      throw ParameterError("(file)", "the alias *" + name + " at " + at(e.start_mark) +
                                         " lies inside the collection it repeats: the tree "
                                         "would be infinite (node limit " +
                                         std::to_string(kMaxScenarioNodes) + ")");
    }
    count(found->second.nodes, e.start_mark);
    attach(found->second.node, found->second.nodes, e.start_mark);
  }

  void start(const yaml_event_t& e) {
    if (open_.size() >= kMaxScenarioDepth) {
      throw ParameterError("(file)", "nested deeper than the depth limit of a scenario (" +
                                         std::to_string(kMaxScenarioDepth) +
                                         " lists and maps) at " + at(e.start_mark) + ", in " +
                                         where());
    }
    count(1, e.start_mark);
    OpenCollection collection;
    collection.is_map = e.type == YAML_MAPPING_START_EVENT;
    collection.node.reset(
        YAML::Node(collection.is_map ? YAML::NodeType::Map : YAML::NodeType::Sequence));
    const yaml_char_t* anchor =
        collection.is_map ? e.data.mapping_start.anchor : e.data.sequence_start.anchor;
    collection.anchor = text(anchor);
    remember(anchor, collection.node, 1, true);
    open_.push_back(std::move(collection));
  }

  void end(const yaml_event_t& e) {
    const YAML::Node node = open_.back().node;
    const std::size_t nodes = open_.back().nodes;
    const std::string anchor = open_.back().anchor;
    open_.pop_back();
    if (!anchor.empty()) {
      Anchor& entry = anchors_[anchor];
      if (entry.node.is(node)) {  // not redefined inside the collection
        entry.nodes = nodes;
        entry.open = false;
      }
    }
    attach(node, nodes, e.start_mark);
  }

  bool done() const { return have_root_; }
  const YAML::Node& root() const { return root_; }

 private:
  /// Hands a finished node of @p nodes nodes to the collection it belongs to (or makes it the
  /// root).
  void attach(const YAML::Node& node, std::size_t nodes, const yaml_mark_t& mark) {
    // YAML::Node assignment writes into the node referred to; reset() rebinds the handle.
    if (open_.empty()) {
      root_.reset(node);
      have_root_ = true;
      return;
    }
    OpenCollection& parent = open_.back();
    parent.nodes += nodes;
    if (!parent.is_map) {
      parent.node.push_back(node);
    } else if (!parent.have_key) {
      parent.key.reset(node);
      parent.have_key = true;
    } else {
      if (parent.key.IsScalar() && !parent.scalar_keys.insert(parent.key.Scalar()).second) {
        throw ParameterError("(file)", "the key '" + parent.key.Scalar() +
                                           "' appears twice in one map (line " +
                                           std::to_string(mark.line + 1) + ")");
      }
      parent.node.force_insert(parent.key, node);
      parent.have_key = false;
    }
  }

  void remember(const yaml_char_t* anchor, const YAML::Node& node, std::size_t nodes, bool open) {
    if (anchor != nullptr) {
      Anchor& entry = anchors_[text(anchor)];
      entry.node.reset(node);
      entry.nodes = nodes;
      entry.open = open;
    }
  }

  std::map<std::string, Anchor> anchors_;
  std::vector<OpenCollection> open_;
  YAML::Node root_;
  bool have_root_ = false;
  std::size_t total_ = 0;
};

}  // namespace

YAML::Node parseYaml(const std::string& yaml_text, const std::function<bool()>& cancelled) {
  if (yaml_text.size() > kMaxScenarioBytes) {
    throw ParameterError("(file)", "has " + std::to_string(yaml_text.size()) +
                                       " bytes, over the size limit of a scenario (" +
                                       std::to_string(kMaxScenarioBytes) + " bytes)");
  }
  EventParser parser(yaml_text);
  TreeBuilder builder;
  for (std::size_t events = 0; !builder.done(); ++events) {
    if (cancelled && events % kCancelPollEvents == 0 && cancelled()) {
      throw ScenarioLoadCancelled("loading cancelled at " + at(parser.mark()) + ", in " +
                                  builder.where());
    }
    Event event;
    parser.next(event.get());
    const yaml_event_t& e = *event;
    switch (e.type) {
      case YAML_SCALAR_EVENT:
        builder.scalar(e);
        break;
      case YAML_ALIAS_EVENT:
        builder.alias(e);
        break;
      case YAML_SEQUENCE_START_EVENT:
      case YAML_MAPPING_START_EVENT:
        builder.start(e);
        break;
      case YAML_SEQUENCE_END_EVENT:
      case YAML_MAPPING_END_EVENT:
        builder.end(e);
        break;
      case YAML_STREAM_END_EVENT:
        return YAML::Node(YAML::NodeType::Null);  // no document
      case YAML_DOCUMENT_END_EVENT:               // a document with no node
        return YAML::Node(YAML::NodeType::Null);
      case YAML_NO_EVENT:
      case YAML_STREAM_START_EVENT:
      case YAML_DOCUMENT_START_EVENT:
        break;
    }
  }
  return builder.root();
}

std::string readYamlFile(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw ParameterError("(file)", "'" + path + "' is a directory, not a scenario file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > kMaxScenarioBytes) {
    throw ParameterError("(file)", tooLarge(path, std::to_string(size)));
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw ParameterError("(file)", "cannot read '" + path + "'");
  }
  std::string text;
  if (!error) {
    text.reserve(static_cast<std::size_t>(size));
  }
  std::array<char, kReadChunkBytes> chunk{};
  while (file.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || file.gcount() > 0) {
    text.append(chunk.data(), static_cast<std::size_t>(file.gcount()));
    if (text.size() > kMaxScenarioBytes) {
      throw ParameterError("(file)",
                           tooLarge(path, "more than " + std::to_string(kMaxScenarioBytes)));
    }
  }
  if (file.bad()) {
    throw ParameterError("(file)", "cannot read '" + path + "'");
  }
  return text;
}

}  // namespace projection_collision_avoidance::detail
