/// @file
/// qp_solve: the control barrier function filter's QP (doc/math.md, (B3)) from the command line,
/// for test/reference/compare_qp.py, which solves the same problems with cvxopt. No ROS.
///
/// Reads one problem a line from stdin, whitespace-separated:
///   k a_max u_nom(k values) N  then N times  g(k values) b
/// (k = 1, 2 or 3; a_max > 0 or `inf`; the half-spaces g^T u >= b in priority order), solves it
/// with SafetyFilter (one BarrierConstraint per half-space, normal g, bound b) and prints one line:
///   feasible infeasible dropped u*(k values, %.17g) active_count
/// feasible (0/1): u* satisfies every half-space given within CommandProjection's tolerance
/// (kFeasibilityTolerance max(||u_nom||, a_max when finite, ||u*||, |b_j| / ||g_j||) ||g_j||) and
/// ||u*|| <= a_max; infeasible, dropped and active_count: SafetyFilterResult's infeasible (0/1),
/// dropped and active_count. A line that cannot be read, a half-space SafetyFilter::add refuses
/// or an exception prints `error <reason>` instead. Empty lines and lines starting with # are
/// skipped. Exit status: 0, or 1 when some line printed an error. Built without CMake by
///   g++ -std=c++17 -O2 -I include -I /usr/include/eigen3 test/tools/qp_solve.cpp
///       src/core/SafetyFilter.cpp src/core/CommandProjection.cpp -o qp_solve

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/CommandProjection.hpp"
#include "projection_collision_avoidance/core/SafetyFilter.hpp"

namespace pca = projection_collision_avoidance;

namespace {

/// Reads the next token of @p in as a double (strtod: also `inf`, `nan`, hexadecimal).
/// @return false at the end of the line or when the token is not a number
bool readNumber(std::istringstream& in, double* value) {
  std::string token;
  if (!(in >> token)) {
    return false;
  }
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return end != token.c_str() && *end == '\0';
}

/// Reads @p count numbers into the first entries of @p v (the others zero).
bool readVector(std::istringstream& in, int count, Eigen::Vector3d* v) {
  v->setZero();
  for (int i = 0; i < count; ++i) {
    if (!readNumber(in, &(*v)(i))) {
      return false;
    }
  }
  return true;
}

/// Whether @p u satisfies ||u|| <= a_max and every half-space g_j^T u >= b_j (taken with unit
/// normals, the same sets) within the tolerance of the file comment.
bool satisfiesAll(const std::vector<Eigen::Vector3d>& normals, const std::vector<double>& bounds,
                  const Eigen::Vector3d& nominal, double a_max, const Eigen::Vector3d& u) {
  const double norm = pca::euclideanNorm(u);
  if (std::isfinite(a_max) && !(norm <= a_max)) {
    return false;
  }
  const double scale =
      std::max({pca::euclideanNorm(nominal), norm, std::isfinite(a_max) ? a_max : 0.0});
  for (std::size_t j = 0; j < normals.size(); ++j) {
    const double g = pca::euclideanNorm(normals[j]);
    const Eigen::Vector3d n = normals[j] / g;
    const double c = bounds[j] / g;
    const double tol = pca::CommandProjection::kFeasibilityTolerance * std::max(scale, std::abs(c));
    if (!(n.dot(u) >= c - tol)) {
      return false;
    }
  }
  return true;
}

/// Solves the problem on @p line; writes its output line (without the newline) to @p out.
/// @return false when the line printed an error
bool solveLine(const std::string& line, std::string* out) {
  std::istringstream in(line);
  double k_value = 0.0;
  double a_max = 0.0;
  double n_value = 0.0;
  Eigen::Vector3d nominal;
  if (!readNumber(in, &k_value) || !(k_value == 1.0 || k_value == 2.0 || k_value == 3.0)) {
    *out = "error k must be 1, 2 or 3";
    return false;
  }
  const int k = static_cast<int>(k_value);
  if (!readNumber(in, &a_max) || !readVector(in, k, &nominal) || !readNumber(in, &n_value) ||
      !(n_value >= 0.0 && n_value <= pca::CommandProjection::kMaxConstraints &&
        n_value == std::floor(n_value))) {
    *out = "error cannot read a_max, u_nom or N";
    return false;
  }
  pca::SafetyFilter filter(k);
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> bounds;
  for (int j = 0; j < static_cast<int>(n_value); ++j) {
    pca::BarrierConstraint c;
    if (!readVector(in, k, &c.normal) || !readNumber(in, &c.bound) || !filter.add(c)) {
      *out = "error half-space " + std::to_string(j) + " unreadable or refused by add()";
      return false;
    }
    normals.push_back(c.normal);
    bounds.push_back(c.bound);
  }
  std::string rest;
  if (in >> rest) {
    *out = "error trailing input: " + rest;
    return false;
  }
  const pca::SafetyFilterResult r = filter.filter(nominal, a_max);  // throws on a bad a_max
  const bool feasible = satisfiesAll(normals, bounds, nominal, a_max, r.command);
  std::ostringstream text;
  text.precision(17);  // the default float field: %.17g
  text << (feasible ? 1 : 0) << ' ' << (r.infeasible ? 1 : 0) << ' ' << r.dropped;
  for (int i = 0; i < k; ++i) {
    text << ' ' << r.command(i);
  }
  text << ' ' << r.active_count;
  *out = text.str();
  return true;
}

}  // namespace

/// Reads the problems from stdin and prints one line each (see the file comment).
int main() {
  std::ios::sync_with_stdio(false);
  std::string line;
  bool ok = true;
  while (std::getline(std::cin, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') {
      continue;
    }
    std::string out;
    try {
      ok = solveLine(line, &out) && ok;
    } catch (const std::exception& e) {
      out = std::string("error ") + e.what();
      ok = false;
    }
    std::cout << out << '\n';
  }
  return ok ? 0 : 1;
}
