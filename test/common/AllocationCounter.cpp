#include "AllocationCounter.hpp"

#include <atomic>
#include <cstddef>

namespace {
std::atomic<long> g_allocations{0};
// Per thread (static TLS of the executable: reading or writing it never allocates).
thread_local long t_allocations = 0;
thread_local long t_frees = 0;

void counted() {
  ++g_allocations;
  ++t_allocations;
}
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);

void* malloc(std::size_t size) {
  counted();
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  counted();
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  counted();
  return __libc_realloc(pointer, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  counted();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  counted();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** pointer, std::size_t alignment, std::size_t size) {
  counted();
  *pointer = __libc_memalign(alignment, size);
  return *pointer == nullptr ? 12 /* ENOMEM */ : 0;
}
void free(void* pointer) {
  if (pointer != nullptr) {
    ++t_frees;
  }
  __libc_free(pointer);
}
}

namespace projection_collision_avoidance {
namespace testing {

long allocationCount() { return g_allocations.load(); }
long threadAllocationCount() { return t_allocations; }
long threadFreeCount() { return t_frees; }

}  // namespace testing
}  // namespace projection_collision_avoidance
