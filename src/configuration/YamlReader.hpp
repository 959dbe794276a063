#pragma once

/// @file
/// Typed, key-tracking access to one YAML map of a scenario (internal to the configuration
/// library).
/// Every read marks its key as known; finish() refuses the keys nobody read.

#include <cmath>
#include <cstddef>
#include <limits>
#include <set>
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance::detail {

class YamlReader {
 public:
  /// @param node a YAML map
  /// @param path dotted path of the map ("" for the root)
  YamlReader(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {}

  /// Dotted path of an entry of this map.
  std::string key(const std::string& name) const {
    return path_.empty() ? name : path_ + "." + name;
  }

  /// True when the entry is present and not null; a present key counts as known.
  bool has(const std::string& name) {
    const YAML::Node& node = node_;
    if (!node[name]) {
      return false;
    }
    used_.insert(name);
    return !node[name].IsNull();
  }

  /// Marks the entry as known without reading it: a section that another reader reads (the
  /// simulation's sections, when only a follower's configuration is read).
  void skip(const std::string& name) { used_.insert(name); }

  YamlReader map(const std::string& name) {
    const YAML::Node child = required(name);
    if (!child.IsMap()) {
      throw ParameterError(key(name), "must be a map");
    }
    return {child, key(name)};
  }

  std::string string(const std::string& name) { return scalar<std::string>(name, "a string"); }
  double number(const std::string& name) { return scalar<double>(name, "a number"); }
  bool boolean(const std::string& name) { return scalar<bool>(name, "true or false"); }

  /// A whole number that fits an int (a YAML integer, or a real with no fractional part).
  int integer(const std::string& name) {
    const double value = number(name);
    const YAML::Node& node = node_;
    const std::string text = "'" + node[name].Scalar() + "'";
    if (!(std::abs(value) <= static_cast<double>(std::numeric_limits<int>::max()))) {
      throw ParameterError(key(name), "must be a whole number within +-" +
                                          std::to_string(std::numeric_limits<int>::max()) +
                                          ", got " + text);
    }
    if (value != std::trunc(value)) {
      throw ParameterError(key(name), "must be a whole number, got " + text);
    }
    return static_cast<int>(value);
  }

  /// A list of numbers.
  Eigen::VectorXd vector(const std::string& name) {
    const YAML::Node child = required(name);
    return toVector(child, key(name));
  }

  /// A list of @p size numbers, or one number repeated @p size times.
  Eigen::VectorXd vectorOrScalar(const std::string& name, Eigen::Index size) {
    const YAML::Node child = required(name);
    if (child.IsScalar()) {
      return Eigen::VectorXd::Constant(size, toNumber(child, key(name)));
    }
    return toVector(child, key(name));
  }

  /// A list of rows, or a number s meaning s * I (0 meaning the zero matrix of any shape).
  /// rows/cols < 0 mean "not known here"; a number needs the size to be known.
  Eigen::MatrixXd matrix(const std::string& name, Eigen::Index rows, Eigen::Index cols) {
    const YAML::Node child = required(name);
    if (child.IsScalar()) {
      const double value = toNumber(child, key(name));
      if (value == 0.0 && rows >= 0 && cols >= 0) {
        return Eigen::MatrixXd::Zero(rows, cols);
      }
      const Eigen::Index size = rows >= 0 ? rows : cols;
      if (size < 0 || (rows >= 0 && cols >= 0 && rows != cols)) {
        throw ParameterError(key(name),
                             "a number stands for s * I and needs a square matrix "
                             "of known size; give a list of rows");
      }
      return value * Eigen::MatrixXd::Identity(size, size);
    }
    if (!child.IsSequence() || child.size() == 0) {
      throw ParameterError(key(name), "must be a list of rows or a number");
    }
    const auto row_count = static_cast<Eigen::Index>(child.size());
    Eigen::MatrixXd result;
    for (Eigen::Index i = 0; i < row_count; ++i) {
      const YAML::Node row = child[static_cast<std::size_t>(i)];
      if (!row.IsSequence()) {
        throw ParameterError(key(name), "must be a list of rows, e.g. [[1.0, 1.4]]");
      }
      const Eigen::VectorXd values = toVector(row, key(name) + "." + std::to_string(i));
      if (i == 0) {
        result.resize(row_count, values.size());
      } else if (values.size() != result.cols()) {
        throw ParameterError(key(name), "rows have different lengths");
      }
      result.row(i) = values.transpose();
    }
    return result;
  }

  /// Number of items of a list (the key is then known).
  std::size_t sequenceSize(const std::string& name) {
    const YAML::Node child = required(name);
    if (!child.IsSequence()) {
      throw ParameterError(key(name), "must be a list");
    }
    return child.size();
  }

  /// Item @p index of a list of maps.
  YamlReader item(const std::string& name, std::size_t index) {
    const YAML::Node child = required(name)[index];
    const std::string item_key = key(name) + "." + std::to_string(index);
    if (!child.IsMap()) {
      throw ParameterError(item_key, "must be a map");
    }
    return {child, item_key};
  }

  /// Refuses every key of this map that was not read.
  void finish() const {
    for (const auto& entry : node_) {
      if (!entry.first.IsScalar()) {
        throw ParameterError(path_.empty() ? "(root)" : path_,
                             "has a key that is not a name (a list or a map)");
      }
      const std::string& name = entry.first.Scalar();
      if (used_.count(name) == 0) {
        throw ParameterError(key(name), "unknown key");
      }
    }
  }

 private:
  YAML::Node required(const std::string& name) {
    const YAML::Node& node = node_;
    const YAML::Node child = node[name];
    if (!child || child.IsNull()) {
      throw ParameterError(key(name), "missing");
    }
    used_.insert(name);
    return child;
  }

  /// True for a scalar that YAML types as a string: quoted ("0.2", '1') or tagged !!str, and
  /// every string parameter converted from ROS (see toYaml()).
  static bool isString(const YAML::Node& node) {
    return node.IsScalar() && (node.Tag() == "!" || node.Tag() == "tag:yaml.org,2002:str");
  }

  template <typename T>
  T scalar(const std::string& name, const char* what) {
    const YAML::Node child = required(name);
    if (!child.IsScalar()) {
      throw ParameterError(key(name), std::string("must be ") + what);
    }
    if (!std::is_same<T, std::string>::value && isString(child)) {
      throw ParameterError(
          key(name), std::string("must be ") + what + ", got the string '" + child.Scalar() + "'");
    }
    try {
      return child.as<T>();
    } catch (const YAML::Exception&) {
      throw ParameterError(key(name),
                           std::string("must be ") + what + ", got '" + child.Scalar() + "'");
    }
  }

  static double toNumber(const YAML::Node& node, const std::string& key) {
    if (isString(node)) {
      throw ParameterError(key, "must be a number, got the string '" + node.Scalar() + "'");
    }
    try {
      return node.as<double>();
    } catch (const YAML::Exception&) {
      throw ParameterError(key, "must be a number, got '" + node.Scalar() + "'");
    }
  }

  static Eigen::VectorXd toVector(const YAML::Node& node, const std::string& key) {
    if (!node.IsSequence()) {
      throw ParameterError(key, "must be a list of numbers");
    }
    Eigen::VectorXd result(static_cast<Eigen::Index>(node.size()));
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (!node[i].IsScalar()) {
        throw ParameterError(key, "must be a list of numbers");
      }
      result(static_cast<Eigen::Index>(i)) = toNumber(node[i], key);
    }
    return result;
  }

  YAML::Node node_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace projection_collision_avoidance::detail
