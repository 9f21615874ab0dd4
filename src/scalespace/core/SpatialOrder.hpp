#pragma once
// Spatial (Morton / Z-order) ordering of a point cloud. Drivers reorder positions, normals and
// attributes with spatialOrder() before building the index and iterating over points, so that
// points processed one after the other, and their neighbours, are close in memory. The gain is
// measured by bench/bench_spatial_index.cpp.
//
//   std::vector<Index> order = spatialOrder(cloud.positions());
//   PointCloud sorted = cloud.subset(order);          // or applyPermutation(values, order)
//   ... compute per-point results r on `sorted` ...
//   r = applyPermutation(r, invertPermutation(order));  // back to the input order
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// A permutation `order` such that points[order[0]], points[order[1]], ... follow a Morton
/// (Z-order) curve over the bounding box (21 bits per axis). Deterministic: codes are computed in
/// parallel, ties are broken by index. Points with a non-finite coordinate come last, in index
/// order.
std::vector<Index> spatialOrder(const std::vector<Vec3>& points);

/// A permutation whose every prefix is spread evenly over the points: first one point per occupied
/// cell of the Morton grid's coarsest level, then one per newly occupied cell of each finer level
/// (the levels of an octree over the bounding cube), then the points that share a finest cell.
/// Within a level the points are visited along the curve with a golden-ratio stride, so that a
/// prefix ending inside a level is still even. Deterministic for any thread count; non-finite
/// points come last. The viewer draws a prefix of it as its level of detail.
std::vector<Index> coarseToFineOrder(const std::vector<Vec3>& points);

/// The Morton code of a point whose coordinates are quantised to [0, 2^21) per axis.
std::uint64_t mortonCode(std::uint32_t x, std::uint32_t y, std::uint32_t z);

/// out[i] = values[order[i]]. Throws OptionError if the sizes differ.
template <class T>
std::vector<T> applyPermutation(const std::vector<T>& values, const std::vector<Index>& order) {
  if (values.size() != order.size())
    throw OptionError("applyPermutation: " + std::to_string(values.size()) + " values but a " +
                      std::to_string(order.size()) + "-element permutation");
  std::vector<T> out;
  out.reserve(values.size());
  for (Index i : order) out.push_back(values.at(i));
  return out;
}

/// The inverse permutation: inverse[order[i]] = i, so that applyPermutation(applyPermutation(v,
/// order), inverse) == v. Throws OptionError if `order` is not a permutation.
std::vector<Index> invertPermutation(const std::vector<Index>& order);

}  // namespace scalespace
