#pragma once
// "Jets" baseline (Cazals & Pouget 2005; Sec. 1.4.3): unweighted osculating jet of degree 2 over
// all neighbours within t, via CGAL::Monge_via_jet_fitting (d_fitting = 2, d_monge = 2). CGAL
// fits at the first point of the range, so the neighbour nearest to x is placed first; the
// reported projection is the Monge origin (that point projected onto the jet). Curvature signs
// follow the reference normal: the Monge normal is flipped to agree with the weighted mean of the
// input normals (when there are any) and curvatures are positive when the surface bends away from
// it (sphere with outward normals: +1/r).
#include <vector>

#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace {

LocalFit fitJet(const Vec3& x, double t, const std::vector<Neighbor>& nbrs,
                const SurfaceSamples& samples, int minNeighbors);

}  // namespace scalespace
