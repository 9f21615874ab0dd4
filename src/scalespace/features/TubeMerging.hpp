#pragma once
// (Not in the thesis.) The tubes of one scale that are pieces of one tube, merged: noise breaks
// the minimal-curvature lines along a pipe, each piece grows its own region (Eq. 3.10), and a
// strand of a noisy cable came in three pieces. CylinderDetection runs it on every scale.
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/features/LineAnisotropy.hpp"
#include "scalespace/features/TubeFit.hpp"
#include "scalespace/features/TubeSplitting.hpp"

namespace scalespace {

/// Per point, the region of the tube holding it, or -1 (regions that are no tube hold none).
std::vector<int> tubeOwners(std::size_t pointCount, const std::vector<TubeFit>& tubes,
                            const std::vector<std::vector<Index>>& regions);

/// Tubes whose regions touch (k-NN edges of `graph` between them) are merged when their radii
/// agree within 25% and their union is still one tube: fitTube (on `field`'s normals and kappa1
/// at scale t) accepts it with an RMS at most 1.25 x the larger of theirs plus 2% of the radius.
/// Two touching strands side by side are no tube and stay apart. Pairs are tried by decreasing
/// number of edges between them, then by index, so the result is deterministic. The merged tube
/// takes the lower index (its region the union, sorted); the other is left with an empty region
/// and TubeRejection::Merged.
/// `apart` (may be empty): per region, a group id; two tubes of one group >= 0 are the parts of
/// one region split by their axes (features/TubeSplitting) and merge only where they may be
/// pieces of one strand (mayBeOneStrand with `split`): side by side, a curved axis can zigzag
/// between two strands and fit both as one tube; end to end but aside, it bridges the runs of two
/// strands that a scan from one side sees in turn.
void mergeTouchingTubes(const KnnGraph& graph, const std::vector<Vec3>& positions,
                        const std::vector<Vec3>& normals, const LineAnisotropyField& field,
                        double t, const TubeFitOptions& options, std::vector<TubeFit>& tubes,
                        std::vector<std::vector<Index>>& regions,
                        const std::vector<int>& apart = {}, const TubeSplitOptions& split = {});

}  // namespace scalespace
