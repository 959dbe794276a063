#include "projection_collision_avoidance/sim/SignalProfile.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "projection_collision_avoidance/core/ValidationChecks.hpp"

namespace projection_collision_avoidance {

Eigen::VectorXd SignalProfile::value(double t, Eigen::Index size) const {
  Eigen::VectorXd result = Eigen::VectorXd::Zero(size);
  addTo(t, result);
  return result;
}

void SignalProfile::addTo(double t, Eigen::Ref<Eigen::VectorXd> result) const {
  addPulsesTo(t, result);
  addSinusoidsTo(t, result);
}

void SignalProfile::addPulsesTo(double t, Eigen::Ref<Eigen::VectorXd> result) const {
  for (const Pulse& pulse : pulses) {
    if (pulse.start <= t && t < pulse.end) {
      result += pulse.vector;
    }
  }
}

void SignalProfile::addSinusoidsTo(double t, Eigen::Ref<Eigen::VectorXd> result) const {
  for (const Sinusoid& wave : sinusoids) {
    result += wave.amplitude * std::sin(2.0 * M_PI * wave.frequency * t + wave.phase);
  }
}

bool SignalProfile::hasEdgeWithin(double t0, double t1) const {
  for (const Pulse& pulse : pulses) {
    if ((pulse.start > t0 && pulse.start < t1) || (pulse.end > t0 && pulse.end < t1)) {
      return true;
    }
  }
  return false;
}

std::vector<double> SignalProfile::edgesWithin(double t0, double t1) const {
  std::vector<double> edges;
  for (const Pulse& pulse : pulses) {
    for (const double edge : {pulse.start, pulse.end}) {
      if (edge > t0 && edge < t1) {
        edges.push_back(edge);
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

void SignalProfile::validate(const std::string& key, Eigen::Index size) const {
  for (std::size_t i = 0; i < pulses.size(); ++i) {
    const std::string prefix = key + ".pulses." + std::to_string(i);
    detail::requireFinite(prefix + ".start", pulses[i].start);
    detail::requireFinite(prefix + ".end", pulses[i].end);
    if (!(pulses[i].start < pulses[i].end)) {
      throw ParameterError(prefix + ".end", "must be later than start");
    }
    detail::requireVector(prefix + ".vector", pulses[i].vector, size);
  }
  for (std::size_t i = 0; i < sinusoids.size(); ++i) {
    const std::string prefix = key + ".sinusoids." + std::to_string(i);
    detail::requireVector(prefix + ".amplitude", sinusoids[i].amplitude, size);
    detail::requireFinite(prefix + ".frequency", sinusoids[i].frequency);
    detail::requireFinite(prefix + ".phase", sinusoids[i].phase);
  }
}

}  // namespace projection_collision_avoidance
