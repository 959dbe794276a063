/// A control step allocates no memory. The C allocation functions are replaced by counting
/// ones that forward to glibc's, so every heap allocation is seen: operator new, std::allocator
/// and Eigen's aligned_malloc all end in malloc. (Not for sanitizer builds, which replace malloc
/// themselves.)

#include <atomic>
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "projection_collision_avoidance/ControllerDesign.hpp"
#include "projection_collision_avoidance/FollowerController.hpp"
#include "projection_collision_avoidance/RuntimeFollowerController.hpp"
#include "projection_collision_avoidance/ScenarioEmbedding.hpp"

#include "TestScenarios.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);

void* malloc(std::size_t size) {
  ++g_allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  ++g_allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  ++g_allocations;
  return __libc_realloc(pointer, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  ++g_allocations;
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  ++g_allocations;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** pointer, std::size_t alignment, std::size_t size) {
  ++g_allocations;
  *pointer = __libc_memalign(alignment, size);
  return *pointer == nullptr ? 12 /* ENOMEM */ : 0;
}
void free(void* pointer) { __libc_free(pointer); }
}

namespace projection_collision_avoidance {
namespace {

/// Runs @p steps control steps (each with and without the leader's input, and as many fallback
/// steps) on measurements inside and far outside the bound (so both the plain and the projected
/// drift run) and returns the allocations counted during them.
template <typename Dims>
long allocationsDuringSteps(const ControllerDesign& design, int steps) {
  FollowerController<Dims> controller(design);
  typename Dims::OutputVector y(design.parameters.model.outputDimension());
  typename Dims::InputVector u1(design.parameters.model.inputDimension());
  u1.setConstant(0.3);
  const long before = g_allocations.load();
  double sink = 0.0;
  for (int k = 0; k < steps; ++k) {
    y.setConstant((k / 50) % 2 == 0 ? 0.2 : 7.0);
    sink += controller.step(y).command(0);
    sink += controller.step(y, u1).command(0);
    sink += controller.stepFallback().command(0);
    sink += controller.stepFallback(u1).command(0);
  }
  const long after = g_allocations.load();
  EXPECT_TRUE(std::isfinite(sink));
  return after - before;
}

ControllerDesign designFor(int axes, bool share) {
  Scenario scenario = loadScenarioFile(testing::scenarioPath("paper_run2.yaml"));
  scenario.controller.estimator_substeps = 3;
  scenario.controller.leader_input_in_command = share;
  scenario.controller.leader_input_in_estimator = share;
  if (axes > 1) {
    scenario = embedAlongDirection(scenario, Eigen::VectorXd::Ones(axes));
  }
  return ControllerDesign::create(scenario.controller);
}

TEST(NoAllocation, CounterSeesAllocations) {
  const long before = g_allocations.load();
  Eigen::VectorXd heap = Eigen::VectorXd::Ones(100);
  const long after_eigen = g_allocations.load();
  std::vector<double> vector(100, 1.0);
  const long after_vector = g_allocations.load();
  EXPECT_GE(after_eigen - before, 1);
  EXPECT_GE(after_vector - after_eigen, 1);
  EXPECT_EQ(heap.sum() + vector.back(), 101.0);
}

TEST(NoAllocation, ControlStepsOfFixedSizeControllers) {
  for (const bool share : {false, true}) {
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator1D>(designFor(1, share), 1000), 0);
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator2D>(designFor(2, share), 1000), 0);
    EXPECT_EQ(allocationsDuringSteps<DoubleIntegrator3D>(designFor(3, share), 1000), 0);
  }
}

TEST(NoAllocation, ControlStepsOfTheRuntimeController) {
  for (const int axes : {1, 3}) {
    RuntimeFollowerController controller(designFor(axes, true));
    Eigen::VectorXd y = Eigen::VectorXd::Constant(2 * axes, 0.2);
    const Eigen::VectorXd u1 = Eigen::VectorXd::Constant(axes, 0.3);
    controller.step(y);
    const long before = g_allocations.load();
    for (int k = 0; k < 1000; ++k) {
      y.setConstant((k / 50) % 2 == 0 ? 0.2 : 7.0);
      controller.step(y);
      controller.step(y, u1);
      controller.stepFallback();
      controller.stepFallback(u1);
    }
    EXPECT_EQ(g_allocations.load() - before, 0) << axes << " axes";
  }
}

TEST(NoAllocation, ControlStepsOfTheGenericController) {
  EXPECT_EQ(allocationsDuringSteps<GenericDimensions>(designFor(3, true), 1000), 0);
}

}  // namespace
}  // namespace projection_collision_avoidance
