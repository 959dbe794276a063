#pragma once

/// @file
/// Counts heap allocations. Linking AllocationCounter.cpp into a binary replaces the C allocation
/// functions by counting ones that forward to glibc's, so every heap allocation is seen:
/// operator new, std::allocator and Eigen's aligned_malloc all end in malloc. (Not for sanitizer
/// builds, which replace malloc themselves.)

namespace projection_collision_avoidance {
namespace testing {

/// Allocations (malloc, calloc, realloc, memalign, aligned_alloc, posix_memalign) since start.
long allocationCount();
/// Allocations made by the calling thread since it started.
long threadAllocationCount();
/// Blocks freed (free of a non-null pointer) by the calling thread since it started.
long threadFreeCount();

}  // namespace testing
}  // namespace projection_collision_avoidance
