#include "YamlParser.hpp"

#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <yaml.h>

#include "projection_collision_avoidance/ParameterError.hpp"

namespace projection_collision_avoidance::detail {
namespace {

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
      throw ParameterError("(file)",
                           why + " at line " + std::to_string(parser_.problem_mark.line + 1) +
                               ", column " + std::to_string(parser_.problem_mark.column + 1));
    }
  }

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
};

}  // namespace

YAML::Node parseYaml(const std::string& yaml_text) {
  EventParser parser(yaml_text);
  std::map<std::string, YAML::Node> anchors;
  std::vector<OpenCollection> open;
  YAML::Node root;
  bool have_root = false;
  // Hands a finished node to the collection it belongs to (or makes it the root).
  const auto attach = [&](const YAML::Node& node, const yaml_mark_t& mark) {
    // YAML::Node assignment writes into the node referred to; reset() rebinds the handle.
    if (open.empty()) {
      root.reset(node);
      have_root = true;
      return;
    }
    OpenCollection& parent = open.back();
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
  };
  const auto remember = [&](const yaml_char_t* anchor, const YAML::Node& node) {
    if (anchor != nullptr) {
      anchors[text(anchor)].reset(node);
    }
  };

  while (!have_root) {
    Event event;
    parser.next(event.get());
    const yaml_event_t& e = *event;
    switch (e.type) {
      case YAML_SCALAR_EVENT: {
        const YAML::Node node = scalarNode(e);
        remember(e.data.scalar.anchor, node);
        attach(node, e.start_mark);
        break;
      }
      case YAML_ALIAS_EVENT: {
        const auto found = anchors.find(text(e.data.alias.anchor));
        if (found == anchors.end()) {
          throw ParameterError("(file)", "not valid YAML: the alias *" + text(e.data.alias.anchor) +
                                             " names no anchor before it (line " +
                                             std::to_string(e.start_mark.line + 1) + ")");
        }
        attach(found->second, e.start_mark);
        break;
      }
      case YAML_SEQUENCE_START_EVENT:
      case YAML_MAPPING_START_EVENT: {
        OpenCollection collection;
        collection.is_map = e.type == YAML_MAPPING_START_EVENT;
        collection.node.reset(
            YAML::Node(collection.is_map ? YAML::NodeType::Map : YAML::NodeType::Sequence));
        remember(collection.is_map ? e.data.mapping_start.anchor : e.data.sequence_start.anchor,
                 collection.node);
        open.push_back(std::move(collection));
        break;
      }
      case YAML_SEQUENCE_END_EVENT:
      case YAML_MAPPING_END_EVENT: {
        const YAML::Node node = open.back().node;
        open.pop_back();
        attach(node, e.start_mark);
        break;
      }
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
  return root;
}

}  // namespace projection_collision_avoidance::detail
