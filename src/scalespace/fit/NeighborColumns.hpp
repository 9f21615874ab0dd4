#pragma once
// The neighbours of one fit as columns (structure of arrays): what the APSS passes read, eight
// at a time on CPUs with AVX-512 (fit/RobustReweighting, fit/DerivativeSums). They are gathered
// straight into columns, from samples stored as columns too (fit/NeighborhoodCache), so that no
// pass has to de-interleave packed x, y, z triples.
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "scalespace/core/Types.hpp"
#include "scalespace/fit/SimdKernel.hpp"

namespace scalespace {

/// std::allocator whose resize() leaves new elements uninitialised: the columns are sized for
/// every candidate, then written, once per fit; zeroing them first showed in the profile.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using Column = std::vector<double, UninitializedAllocator<double>>;

/// Neighbours as columns, offsets q = p - y from the evaluation point y. The columns keep their
/// length between fits (at least size(); entries past size() are stale): resizing eight vectors
/// twice per fit showed in the profile.
class NeighborColumns {
 public:
  Column qx, qy, qz, nx, ny, nz;
  Column d2;      // |q|^2
  Column weight;  // kernel weight w(|q|) (Eq. 1.6)
  std::size_t size() const { return size_; }
  void clear() { size_ = 0; }
  void push(const Vec3& q, const Vec3& n, double kernelWeight);
  /// Makes the columns at least n long; size() and the first size() entries are kept.
  void reserve(std::size_t n);
  /// The first n entries (n <= the columns' length) are the neighbours.
  void setSize(std::size_t n) { size_ = n; }

 private:
  std::size_t size_ = 0;
};

/// Samples (positions and unit normals) as columns.
struct SampleColumns {
  Column px, py, pz, nx, ny, nz;
  std::size_t size() const { return px.size(); }
};

/// Replaces `out` by the samples with |p - y|^2 < t^2 (the spatial index's radius test), in
/// their order in `samples` (which must have normals: the APSS fits' samples), as offsets q = p - y
/// with their normals, |q|^2 and kernel weights (r - 1)^2, r = |q|^2 / t^2 (Eq. 1.6). `kernel`:
/// fit/SimdKernel.hpp (the AVX-512 version compresses eight candidates at a time; |q|^2 may differ
/// from the portable one in the last bit).
void gatherWithin(const SampleColumns& samples, const Vec3& y, double t, NeighborColumns& out,
                  SimdKernel kernel = SimdKernel::Auto);

}  // namespace scalespace
