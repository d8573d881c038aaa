#include "sunvo/runtime/alloc_counter.hpp"

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <new>

// glibc's own allocator entry points; the definitions below shadow the public names.
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t n, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void* __libc_valloc(std::size_t size);
void* __libc_pvalloc(std::size_t size);
void __libc_free(void* p);
}

namespace {

std::atomic<std::uint64_t> g_count{0};
std::atomic<std::uint64_t> g_bytes{0};
// Per thread: a constant-initialised thread_local (static TLS, no allocation on first use).
thread_local std::uint64_t t_count = 0;

inline void record(std::size_t bytes) {
  ++t_count;
  g_count.fetch_add(1, std::memory_order_relaxed);
  g_bytes.fetch_add(bytes, std::memory_order_relaxed);
}

}  // namespace

extern "C" {

void* malloc(std::size_t size) {
  record(size);
  return __libc_malloc(size);
}

void* calloc(std::size_t n, std::size_t size) {
  record(n * size);
  return __libc_calloc(n, size);
}

void* realloc(void* p, std::size_t size) {
  record(size);
  return __libc_realloc(p, size);
}

void* memalign(std::size_t alignment, std::size_t size) {
  record(size);
  return __libc_memalign(alignment, size);
}

void* aligned_alloc(std::size_t alignment, std::size_t size) {
  record(size);
  return __libc_memalign(alignment, size);
}

int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  // POSIX: the alignment must be a power of two and a multiple of sizeof(void*).
  if (alignment == 0 || (alignment & (alignment - 1)) != 0 || alignment % sizeof(void*) != 0) {
    return EINVAL;
  }
  record(size);
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}

void* valloc(std::size_t size) {
  record(size);
  return __libc_valloc(size);
}

void* pvalloc(std::size_t size) {
  record(size);
  return __libc_pvalloc(size);
}

void free(void* p) {
  __libc_free(p);
}

}  // extern "C"

// Replaceable allocation functions, routed through the counted C functions above.
namespace {

void* newImpl(std::size_t size) {
  if (size == 0) size = 1;
  void* p = malloc(size);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

void* newAlignedImpl(std::size_t size, std::align_val_t al) {
  if (size == 0) size = 1;
  auto alignment = static_cast<std::size_t>(al);
  if (alignment < sizeof(void*)) alignment = sizeof(void*);
  void* p = nullptr;
  if (posix_memalign(&p, alignment, size) != 0) throw std::bad_alloc();
  return p;
}

}  // namespace

void* operator new(std::size_t size) {
  return newImpl(size);
}
void* operator new[](std::size_t size) {
  return newImpl(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return malloc(size == 0 ? 1 : size);
}
void* operator new(std::size_t size, std::align_val_t al) {
  return newAlignedImpl(size, al);
}
void* operator new[](std::size_t size, std::align_val_t al) {
  return newAlignedImpl(size, al);
}
void* operator new(std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  try {
    return newAlignedImpl(size, al);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  try {
    return newAlignedImpl(size, al);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept {
  free(p);
}
void operator delete[](void* p) noexcept {
  free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  free(p);
}

namespace sunvo::runtime {

std::uint64_t allocationCount() {
  return g_count.load(std::memory_order_relaxed);
}
std::uint64_t threadAllocationCount() {
  return t_count;
}
std::uint64_t allocatedBytes() {
  return g_bytes.load(std::memory_order_relaxed);
}

bool allocCounterActive() {
  // Through a volatile pointer so that the compiler cannot elide the malloc/free pair.
  void* (*volatile alloc)(std::size_t) = &malloc;
  const std::uint64_t before = allocationCount();
  void* p = alloc(16);
  const bool counted = allocationCount() > before;
  free(p);
  return counted;
}

}  // namespace sunvo::runtime
