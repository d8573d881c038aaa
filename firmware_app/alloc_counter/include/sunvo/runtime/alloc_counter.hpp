#pragma once
// A heap allocation counter for benchmarks and tests. Linking the object library
// sunvo_alloc_counter into an executable replaces malloc, calloc, realloc, posix_memalign,
// aligned_alloc, memalign, valloc, pvalloc, free and every replaceable operator new/delete with
// thin wrappers around glibc's __libc_* functions that count each allocation call (process-wide,
// all threads). operator new is routed through the counted malloc/aligned_alloc, so each
// allocation is counted exactly once. Not for sanitizer builds (ASan owns malloc there).

#include <cstdint>

namespace sunvo::runtime {

// Allocation calls (malloc, calloc, realloc, the aligned forms, operator new) since start.
std::uint64_t allocationCount();
// Allocation calls made by the calling thread since it started.
std::uint64_t threadAllocationCount();
// Bytes requested by those calls (all threads).
std::uint64_t allocatedBytes();
// True when this executable's malloc is the counting one (checked by a real malloc call).
bool allocCounterActive();

// Counts allocations made while it lives: AllocationScope s; ...; s.count().
class AllocationScope {
 public:
  AllocationScope() : start_(allocationCount()) {}
  std::uint64_t count() const { return allocationCount() - start_; }

 private:
  std::uint64_t start_;
};

}  // namespace sunvo::runtime
