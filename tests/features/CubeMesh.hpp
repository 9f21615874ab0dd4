#pragma once
// The unit cube as a triangle mesh whose faces are n x n grids of squares (two triangles each),
// triangles turned outwards: the mesh protocol of Sec. 3.4.1 needs vertices along the edges.
// Shared by the features tests and the CLI's.
#include <Eigen/Geometry>
#include <array>
#include <utility>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace::test {

inline void cubeMesh(int n, std::vector<Vec3>& vertices,
                     std::vector<std::array<Index, 3>>& triangles) {
  auto index = [&](const Vec3& p) {
    for (std::size_t v = 0; v < vertices.size(); ++v)
      if ((vertices[v] - p).norm() < 1e-9) return Index(v);
    vertices.push_back(p);
    return Index(vertices.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Vec3 u = Vec3::Zero(), v = Vec3::Zero(), o = Vec3::Zero();
      u[(axis + 1) % 3] = 1.0 / n;
      v[(axis + 2) % 3] = 1.0 / n;
      o[axis] = side;
      if (side == 0) std::swap(u, v);  // (u x v) along -axis on that side: outwards
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Vec3 p = o + i * u + j * v;
          const Index a = index(p), b = index(p + u), c = index(p + u + v), d = index(p + v);
          triangles.push_back({a, b, c});
          triangles.push_back({a, c, d});
        }
    }
}

}  // namespace scalespace::test
