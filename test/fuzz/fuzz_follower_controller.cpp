/// libFuzzer target on the core controller: a parameter set and a sequence of calls, both decoded
/// from the input, drive DynamicFollowerController (and, for some inputs, a
/// FollowerController<GenericDimensions> alongside). ControllerDesign::create() refusing the
/// parameters (ParameterError) is a valid outcome; any other exception, a sanitizer report or a
/// violated invariant aborts. After every call:
///  - every entry of the command is finite, and ||u_2|| <= acceleration_limit (1 + 1e-12) when the
///    limit is finite;
///  - the estimate is finite and ||xi_hat|| <= xi_max exactly (in euclideanNorm(), the norm the
///    estimator's guarantee is stated in), also the status's copy of it;
///  - a rejected measurement ran the fallback.
///
/// Input layout (test/fuzz/make_corpus.py writes seeds in it):
///   bytes [0, 64)  the parameter header: bytes 0..15 select the model kind and options (see
///                  Header), the bytes from 16 on are read one after the other for the gains,
///                  separation and scales. A zero byte gives a sane default everywhere, so
///                  mostly-valid parameter sets are the rule.
///   bytes [64, ..) operations: one byte each (low 4 bits: which call, high 4 bits: a repeat
///                  count), followed by the values it needs.
/// Build and run: scripts/sanitize.sh.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>

#include <Eigen/Core>
#include <Eigen/QR>

#include "projection_collision_avoidance/core/BallConstraint.hpp"
#include "projection_collision_avoidance/core/ControllerDesign.hpp"
#include "projection_collision_avoidance/core/DynamicFollowerController.hpp"
#include "projection_collision_avoidance/core/FollowerController.hpp"
#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace pca = projection_collision_avoidance;

namespace {

constexpr std::size_t kHeaderSize = 64;
constexpr int kMaxTicks = 1000;  // control periods per input, repeats included
constexpr double kInf = std::numeric_limits<double>::infinity();

/// FUZZ_FOLLOWER_VERBOSE set: print what create() said of each input.
bool verbose() {
  static const bool value = std::getenv("FUZZ_FOLLOWER_VERBOSE") != nullptr;
  return value;
}

[[noreturn]] void fail(const char* what, int tick) {
  std::fprintf(stderr, "fuzz_follower_controller: invariant violated at call %d: %s\n", tick, what);
  std::abort();
}

/// Reads bytes front to back; past the end every read gives zero.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return position_ >= size_; }
  std::uint8_t u8() { return position_ < size_ ? data_[position_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() | (u8() << 8)); }
  std::uint64_t u64() {
    std::uint64_t value = 0;
    for (int i = 0; i < 8; ++i) {
      value |= static_cast<std::uint64_t>(u8()) << (8 * i);
    }
    return value;
  }
  /// In [-1, 1), zero for a zero byte.
  double symmetric() { return static_cast<std::int8_t>(u8()) / 128.0; }
  /// In [-1, 1), finer.
  double symmetric16() { return static_cast<std::int16_t>(u16()) / 32768.0; }
  /// Any 64-bit pattern: every double, NaN and infinities included.
  double anyDouble() {
    const std::uint64_t bits = u64();
    double value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

/// A positive scale around @p center: center * spread^s, s in [-1, 1) (zero bytes: center). Three
/// mode bytes in 256 give an absurd but positive magnitude in [1e-300, 1e300], one any bit
/// pattern (NaN, infinite, negative: mostly refused by create()).
double positive(Reader& in, double center, double spread) {
  const std::uint8_t mode = in.u8();
  if (mode == 255) {
    return in.anyDouble();
  }
  if (mode >= 252) {
    return std::pow(10.0, 300.0 * in.symmetric());
  }
  return center * std::pow(spread, in.symmetric());
}

/// A value in [-scale, scale) (byte 0: zero).
double signedValue(Reader& in, double scale) { return scale * in.symmetric(); }

/// Header bytes 0..15: the structural choices.
struct Header {
  int kind;           // 0..5: double integrator, 6: chain of integrators with a general C,
                      // 7: random (A, B, C)
  int axes;           // 1..3 (chain: 1..2)
  int order;          // chain order 1..3
  int substeps;       // 1..8
  int limit_mode;     // acceleration_limit
  int fallback_mode;  // fallback_gain
  int gains_mode;     // L, Q and S_21 variants
  bool tracker;       // tracker_enabled
  bool leader_in_command;
  bool leader_in_estimator;
  bool zero_initial_estimate;
  bool non_finite;  // measurements and leader inputs may be NaN or infinite
  bool shadow;      // also drive a FollowerController<GenericDimensions>
  int output_mode;  // chain: C square or stacked twice
};

Header readHeader(const std::uint8_t* bytes) {
  Header h;
  h.kind = bytes[0] % 8;
  h.axes = 1 + bytes[1] % 3;
  h.order = 1 + bytes[2] % 3;
  h.substeps = 1 + bytes[3] % 8;
  h.limit_mode = bytes[4];
  h.fallback_mode = bytes[5] % 4;
  h.gains_mode = bytes[6];
  h.tracker = (bytes[7] & 1) == 0;  // byte 0: on
  h.leader_in_command = (bytes[7] & 2) != 0;
  h.leader_in_estimator = (bytes[7] & 4) != 0;
  h.zero_initial_estimate = (bytes[7] & 8) != 0;
  h.non_finite = (bytes[8] % 4) == 3;
  h.shadow = (bytes[9] % 4) == 3;
  h.output_mode = bytes[10] % 2;
  return h;
}

/// Coefficients [k_1, ..., k_r] of (s + w)^r without its leading term, lowest first: the gain of
/// the chain x_1' = x_2, ..., x_r' = -u, u = k . x, that puts every pole at -w.
Eigen::VectorXd chainGain(int order, double w) {
  Eigen::VectorXd k(order);
  // binomial(order, j) w^(order - j) for j = 0 .. order - 1
  double binomial = 1.0;
  for (int j = 0; j < order; ++j) {
    k(j) = binomial * std::pow(w, order - j);
    binomial = binomial * (order - j) / (j + 1);
  }
  return k;
}

/// State feedback for `axes` chains of `order` integrators, states ordered [x_1 of every axis,
/// x_2 of every axis, ...]: every pole at -w_i on axis i.
Eigen::MatrixXd chainFeedback(Reader& in, int axes, int order, double center) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(axes, axes * order);
  for (int i = 0; i < axes; ++i) {
    const Eigen::VectorXd k = chainGain(order, positive(in, center, 30.0));
    for (int j = 0; j < order; ++j) {
      K(i, j * axes + i) = k(j);
    }
  }
  return K;
}

Eigen::MatrixXd lyapunovWeight(Reader& in, int mode, int n) {
  switch (mode % 3) {
    case 0:
      return Eigen::MatrixXd::Identity(n, n);
    case 1: {
      Eigen::VectorXd diagonal(n);
      for (int i = 0; i < n; ++i) {
        diagonal(i) = positive(in, 1.0, 10.0);
      }
      return diagonal.asDiagonal();
    }
    default: {
      Eigen::MatrixXd R(n, n);
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          R(i, j) = signedValue(in, 2.0);
        }
      }
      return R * R.transpose() + positive(in, 0.1, 10.0) * Eigen::MatrixXd::Identity(n, n);
    }
  }
}

Eigen::MatrixXd randomMatrix(Reader& in, int rows, int cols, double scale) {
  Eigen::MatrixXd M(rows, cols);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      M(i, j) = signedValue(in, scale);
    }
  }
  return M;
}

double accelerationLimit(Reader& in, int mode) {
  switch (mode % 8) {
    case 0:
    case 1:
    case 2:
      return kInf;
    case 3:
      switch (in.u8() % 6) {
        case 0:
          return std::numeric_limits<double>::denorm_min();
        case 1:
          return std::numeric_limits<double>::min();
        case 2:
          return std::numeric_limits<double>::max();
        case 3:
          return std::pow(10.0, 300.0 * in.symmetric());
        default:
          return in.anyDouble();
      }
    default:
      return positive(in, 2.0, 30.0);
  }
}

/// The parameter set of the header (kind 0..7); throws ParameterError where the decoding refuses.
pca::ControllerParameters decodeParameters(const Header& h, Reader& in) {
  pca::ControllerParameters p;
  p.control_rate = positive(in, 100.0, 30.0);
  p.alpha = in.u8() == 255 ? in.anyDouble() : 0.2 + 0.79 * in.symmetric();
  if (p.alpha < 0.0) {
    p.alpha = 0.0;  // a fifth of the bytes: the perimeter is zero
  }
  p.epsilon = positive(in, 0.2, 100.0);
  p.estimator_substeps = h.substeps;
  p.initial_estimate =
      h.zero_initial_estimate ? pca::InitialEstimate::kZero : pca::InitialEstimate::kMeasurement;
  p.tracker_enabled = h.tracker;
  p.leader_input_in_command = h.leader_in_command;
  p.leader_input_in_estimator = h.leader_in_estimator;
  p.acceleration_limit = accelerationLimit(in, h.limit_mode);

  if (h.kind <= 5) {  // k-axis double integrator, C = I
    const int k = h.axes;
    p.model = pca::makeDoubleIntegrator(k);
    const int n = 2 * k;
    Eigen::VectorXd w(k), zeta(k), w_e(k), zeta_e(k);
    for (int i = 0; i < k; ++i) {
      w(i) = positive(in, 1.0, 30.0);
      zeta(i) = positive(in, 0.7, 4.0);
      w_e(i) = positive(in, 3.0, 30.0);
      zeta_e(i) = positive(in, 0.7, 4.0);
    }
    p.baseline_gain = pca::doubleIntegratorGain(w, zeta, "fuzz.baseline");
    p.tracker_gain = pca::doubleIntegratorGain(w_e, zeta_e, "fuzz.tracker");
    p.separation = Eigen::VectorXd::Zero(n);
    const double distance = positive(in, 5.0, 100.0);
    for (int i = 0; i < k; ++i) {
      p.separation(i) = distance * (i == 0 ? 1.0 : 0.0) + signedValue(in, distance);
    }
    Eigen::VectorXd observer(n);
    for (int i = 0; i < n; ++i) {
      observer(i) = positive(in, 5.0, 50.0);
    }
    p.estimator_gain = -Eigen::MatrixXd(observer.asDiagonal());
    if (h.gains_mode % 5 == 4) {
      p.estimator_gain += randomMatrix(in, n, n, 1.0);  // may make A_c + L C not Hurwitz
    }
    p.lyapunov_weight = lyapunovWeight(in, h.gains_mode / 5, n);
    p.reference_gain =
        (h.gains_mode / 15) % 2 == 1 ? randomMatrix(in, k, n, 2.0) : Eigen::MatrixXd::Zero(k, n);
    switch (h.fallback_mode) {
      case 1: {
        Eigen::MatrixXd K = Eigen::MatrixXd::Zero(k, n);
        K.leftCols(k).diagonal().setConstant(in.u8() < 128 ? 0.0 : positive(in, 1.0, 10.0));
        K.rightCols(k).diagonal().setConstant(in.u8() < 32 ? 0.0 : positive(in, 1.0, 10.0));
        p.fallback_gain = K;
        break;
      }
      case 2:
        p.fallback_gain = randomMatrix(in, k, n, 5.0);
        break;
      default:
        break;  // the default [0, I]
    }
    return p;
  }

  if (h.kind == 6) {  // chains of integrators seen through an invertible (or stacked) C
    const int k = std::min(h.axes, 2);
    const int r = h.order;
    const int n = k * r;
    pca::AgentModel model;
    model.A = Eigen::MatrixXd::Zero(n, n);
    if (r > 1) {
      model.A.topRightCorner(n - k, n - k).setIdentity();
    }
    model.B = Eigen::MatrixXd::Zero(n, k);
    model.B.bottomRows(k).setIdentity();
    Eigen::MatrixXd T = Eigen::MatrixXd::Identity(n, n) + randomMatrix(in, n, n, 0.4);
    for (int i = 0; i < n; ++i) {
      T.row(i) *= positive(in, 1.0, 10.0);
    }
    if (h.output_mode == 1) {
      Eigen::MatrixXd stacked(2 * n, n);
      stacked << T, Eigen::MatrixXd::Identity(n, n) + randomMatrix(in, n, n, 0.4);
      T = stacked;
    }
    model.C = T;
    model.position_dimension = k;
    p.model = model;
    const Eigen::MatrixXd C_pinv = T.completeOrthogonalDecomposition().pseudoInverse();
    const Eigen::MatrixXd K = chainFeedback(in, k, r, 1.0);
    const Eigen::MatrixXd K_total = chainFeedback(in, k, r, 3.0);
    p.baseline_gain = K * C_pinv;
    p.tracker_gain = (K_total - K) * C_pinv;  // A - B (K + K_e) has its poles at -w_total
    p.estimator_gain = -positive(in, 5.0, 50.0) * C_pinv;
    p.lyapunov_weight = lyapunovWeight(in, h.gains_mode / 5, n);
    p.reference_gain = (h.gains_mode / 15) % 2 == 1
                           ? Eigen::MatrixXd(randomMatrix(in, k, n, 2.0) * C_pinv)
                           : Eigen::MatrixXd::Zero(k, model.C.rows());
    p.separation = Eigen::VectorXd::Zero(n);
    const double distance = positive(in, 5.0, 100.0);
    for (int i = 0; i < k; ++i) {
      p.separation(i) = distance * (i == 0 ? 1.0 : 0.0) + signedValue(in, distance);
    }
    if (h.fallback_mode == 1) {
      p.fallback_gain = chainFeedback(in, k, r, 1.0);
    } else if (h.fallback_mode == 2) {
      p.fallback_gain = randomMatrix(in, k, n, 5.0);
    }
    return p;
  }

  // kind 7: any small (A, B, C); create() refuses most.
  const int n = 1 + in.u8() % 4;
  const int m = 1 + in.u8() % n;
  const int q = 1 + in.u8() % (n + 1);
  pca::AgentModel model;
  model.A = randomMatrix(in, n, n, 2.0);
  model.A.col(0).setZero();  // so that d = e_1 lies in ker(A)
  model.B = randomMatrix(in, n, m, 2.0);
  model.C = randomMatrix(in, q, n, 2.0);
  model.position_dimension = 1 + in.u8() % n;
  p.model = model;
  p.separation = Eigen::VectorXd::Zero(n);
  p.separation(0) = positive(in, 5.0, 100.0);
  p.baseline_gain = randomMatrix(in, m, q, 4.0);
  p.estimator_gain = randomMatrix(in, n, q, 8.0);
  p.tracker_gain = randomMatrix(in, m, q, 4.0);
  p.reference_gain = randomMatrix(in, m, q, 1.0);
  p.lyapunov_weight = lyapunovWeight(in, h.gains_mode / 5, n);
  if (h.fallback_mode == 2) {
    p.fallback_gain = randomMatrix(in, m, n, 5.0);
  }
  return p;
}

/// One measurement or leader-input entry around @p scale: mostly ordinary values, also any
/// finite magnitude (subnormal to DBL_MAX) and, when allowed, NaN and infinities.
double value(Reader& in, double scale, bool non_finite) {
  const std::uint8_t mode = in.u8() % 16;
  if (mode < 10) {
    return scale * in.symmetric16();
  }
  const double sign = (mode & 1) != 0 ? -1.0 : 1.0;
  switch (mode) {
    case 10:
    case 11:
      return sign * std::pow(10.0, 314.0 * (0.5 + 0.5 * in.symmetric16()) - 6.0) *
             (1.0 + in.symmetric());  // up to ~1e308
    case 12: {
      const double any = in.anyDouble();
      return std::isfinite(any) ? any : std::numeric_limits<double>::max();
    }
    case 13:
      return sign * (in.u8() % 2 == 0 ? std::numeric_limits<double>::max()
                                      : std::numeric_limits<double>::denorm_min());
    default: {
      if (!non_finite) {
        return sign * scale * 1e3;
      }
      const std::uint8_t which = in.u8() % 3;
      return which == 0 ? std::numeric_limits<double>::quiet_NaN() : (which == 1 ? kInf : -kInf);
    }
  }
}

Eigen::VectorXd vectorValue(Reader& in, Eigen::Index size, double scale, bool non_finite) {
  Eigen::VectorXd v(size);
  for (Eigen::Index i = 0; i < size; ++i) {
    v(i) = value(in, scale, non_finite);
  }
  return v;
}

/// The norm the controller states its bounds in.
template <typename Derived>
double boundNorm(const Eigen::MatrixBase<Derived>& x) {
  return pca::euclideanNorm(x);
}

/// An independent norm, by scaling: no overflow for finite entries short of a true norm above
/// DBL_MAX.
template <typename Derived>
double scaledNorm(const Eigen::MatrixBase<Derived>& x) {
  const double largest = x.cwiseAbs().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) {
    return largest;
  }
  return largest * (x / largest).norm();
}

template <typename Status, typename Estimate>
void check(const Status& status, const Estimate& estimate, const pca::ControllerDesign& design,
           int tick) {
  if (!status.command.allFinite()) {
    fail("command not finite", tick);
  }
  const double limit = design.parameters.acceleration_limit;
  if (std::isfinite(limit)) {
    if (!(boundNorm(status.command) <= limit * (1.0 + 1e-12)) ||
        !(scaledNorm(status.command) <= limit * (1.0 + 1e-12))) {
      fail("command longer than acceleration_limit", tick);
    }
  }
  if (!estimate.allFinite() || !status.estimate.allFinite()) {
    fail("estimate not finite", tick);
  }
  if (!(boundNorm(estimate) <= design.xi_max) || !(boundNorm(status.estimate) <= design.xi_max)) {
    std::fprintf(stderr, "||xi_hat|| = %a (%a in the status), xi_max = %a\n", boundNorm(estimate),
                 boundNorm(status.estimate), design.xi_max);
    fail("||xi_hat|| > xi_max", tick);
  }
  const double squared = estimate.squaredNorm();  // Eigen's own norm(), where it is exact
  if (squared >= std::numeric_limits<double>::min() &&
      squared <= std::numeric_limits<double>::max() && !(estimate.norm() <= design.xi_max)) {
    fail("||xi_hat|| > xi_max (Eigen's norm())", tick);
  }
  if (!(scaledNorm(estimate) <= design.xi_max * (1.0 + 1e-12))) {
    fail("||xi_hat|| > xi_max (scaled norm)", tick);
  }
  if (!(status.estimate_norm <= design.xi_max)) {
    fail("status.estimate_norm > xi_max", tick);
  }
  if (std::isnan(status.constraint_value)) {
    fail("constraint value NaN", tick);
  }
  if (status.measurement_rejected && !status.fallback) {
    fail("rejected measurement without the fallback", tick);
  }
}

using Shadow = pca::FollowerController<pca::GenericDimensions>;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint8_t header_bytes[kHeaderSize] = {};
  if (size > 0) {
    std::memcpy(header_bytes, data, std::min(size, kHeaderSize));
  }
  const Header header = readHeader(header_bytes);
  Reader header_reader(header_bytes + 16, kHeaderSize - 16);
  Reader in(data + std::min(size, kHeaderSize), size - std::min(size, kHeaderSize));

  std::optional<pca::ControllerDesign> design;
  pca::ControllerParameters parameters;
  try {
    parameters = decodeParameters(header, header_reader);
    design = pca::ControllerDesign::create(parameters);
  } catch (const pca::ParameterError& error) {
    if (verbose()) {
      std::fprintf(stderr, "refused: %s\n", error.what());
    }
    return 0;  // refused: a valid outcome
  }
  if (verbose()) {
    const pca::ControllerParameters& q = design->parameters;
    std::fprintf(stderr,
                 "accepted: kind %d, n %d, m %d, p %d, xi_max %a, epsilon %a, limit %a, period %a, "
                 "substeps %d, tracker %d, leader in command %d / estimator %d, non-finite %d, "
                 "shadow %d\n",
                 header.kind, q.model.stateDimension(), q.model.inputDimension(),
                 q.model.outputDimension(), design->xi_max, q.epsilon, q.acceleration_limit,
                 design->period, q.estimator_substeps, q.tracker_enabled, q.leader_input_in_command,
                 q.leader_input_in_estimator, header.non_finite, header.shadow);
  }

  pca::DynamicFollowerController controller(*design);
  std::optional<Shadow> shadow;
  if (header.shadow) {
    shadow.emplace(*design);
  }
  const Eigen::Index p = controller.outputDimension();
  const Eigen::Index m = controller.inputDimension();
  const double d_norm = scaledNorm(design->parameters.separation);
  const double scale = std::isfinite(d_norm) && d_norm > 0.0 ? d_norm : 1.0;

  int tick = 0;
  while (!in.empty() && tick < kMaxTicks) {
    const std::uint8_t op = in.u8();
    const int repeat = 1 + (op >> 4) * (op >> 4);  // 1 .. 226 periods with the same inputs
    switch (op & 0x0F) {
      case 0:
      case 1:
      case 2:
      case 3:
      case 4:
      case 5: {
        const Eigen::VectorXd y = vectorValue(in, p, scale, header.non_finite);
        for (int r = 0; r < repeat && tick < kMaxTicks; ++r, ++tick) {
          check(controller.step({y}), controller.estimate(), controller.design(), tick);
          if (shadow) {
            check(shadow->step({y}), shadow->estimate(), shadow->design(), tick);
          }
        }
        break;
      }
      case 6:
      case 7:
      case 8:
      case 9: {
        const Eigen::VectorXd y = vectorValue(in, p, scale, header.non_finite);
        const Eigen::VectorXd u1 = vectorValue(in, m, scale, header.non_finite);
        for (int r = 0; r < repeat && tick < kMaxTicks; ++r, ++tick) {
          check(controller.step({y, u1}), controller.estimate(), controller.design(), tick);
          if (shadow) {
            check(shadow->step({y, u1}), shadow->estimate(), shadow->design(), tick);
          }
        }
        break;
      }
      case 10:
      case 11:
        for (int r = 0; r < repeat && tick < kMaxTicks; ++r, ++tick) {
          check(controller.step({}), controller.estimate(), controller.design(), tick);
          if (shadow) {
            check(shadow->step({}), shadow->estimate(), shadow->design(), tick);
          }
        }
        break;
      case 12: {
        const Eigen::VectorXd u1 = vectorValue(in, m, scale, header.non_finite);
        for (int r = 0; r < repeat && tick < kMaxTicks; ++r, ++tick) {
          check(controller.step({std::nullopt, u1}), controller.estimate(), controller.design(),
                tick);
          if (shadow) {
            check(shadow->step({std::nullopt, u1}), shadow->estimate(), shadow->design(), tick);
          }
        }
        break;
      }
      case 13: {  // a new alpha and tracker switch, as dynamic_reconfigure would set them
        pca::ControllerParameters changed = controller.design().parameters;
        const std::uint8_t b = in.u8();
        changed.alpha = b == 255 ? in.anyDouble() : 0.99 * (b / 254.0);
        changed.tracker_enabled = (in.u8() & 1) == 0;
        std::optional<pca::ControllerDesign> next;
        try {
          next = pca::ControllerDesign::create(changed);
        } catch (const pca::ParameterError&) {
          break;  // refused: the old design stays
        }
        pca::DynamicFollowerController replacement(*next);  // state carried over
        replacement.adoptStateOf(controller);
        controller = std::move(replacement);
        if (shadow) {
          Shadow shadow_replacement(*next);
          shadow_replacement.adoptStateOf(*shadow);
          shadow.emplace(shadow_replacement);
          if (!(boundNorm(shadow->estimate()) <= next->xi_max)) {
            fail("shadow: ||xi_hat|| > xi_max after a new design", tick);
          }
        }
        if (!controller.estimate().allFinite() ||
            !(boundNorm(controller.estimate()) <= next->xi_max)) {
          fail("||xi_hat|| > xi_max after adoptStateOf", tick);
        }
        ++tick;
        break;
      }
      case 14:
        controller.reset();
        if (shadow) {
          shadow->reset();
        }
        ++tick;
        break;
      default: {  // a new estimate from outside (also non-finite), as resetEstimate() allows
        if (shadow) {
          const Eigen::VectorXd x =
              vectorValue(in, shadow->estimate().size(), scale, header.non_finite);
          shadow->resetEstimate(x);
          if (!shadow->estimate().allFinite() ||
              !(boundNorm(shadow->estimate()) <= shadow->design().xi_max)) {
            fail("resetEstimate() left ||xi_hat|| > xi_max", tick);
          }
        }
        ++tick;
        break;
      }
    }
  }
  return 0;
}
