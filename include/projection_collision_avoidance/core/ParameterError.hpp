#pragma once

#include <stdexcept>
#include <string>

namespace projection_collision_avoidance {

/// A parameter that cannot be used. key() is its dotted path in the scenario file (for example
/// "controller.alpha"); what() reads "<key>: <reason>".
class ParameterError : public std::invalid_argument {
 public:
  ParameterError(const std::string& key, const std::string& reason)
      : std::invalid_argument(key + ": " + reason), key_(key), reason_(reason) {}

  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string key_;
  std::string reason_;
};

}  // namespace projection_collision_avoidance
