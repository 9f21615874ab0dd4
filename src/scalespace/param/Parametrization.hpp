#pragma once
// `parametrize` in one call (Chapter 4): the scale-space flattening (Sec. 4.3), the domain it
// lands on, and the check of the map for folds and overlaps (the limitation of Sec. 4.3, 4.5),
// with warnings a user must read before trusting the map.
#include <string>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/param/ConformalRelaxation.hpp"
#include "scalespace/param/MapDefects.hpp"
#include "scalespace/param/ParamDomain.hpp"
#include "scalespace/param/ScaleSpaceFlattening.hpp"

namespace scalespace {

struct ParametrizationOptions {
  FlatteningOptions flattening;
  DomainOptions domain;
  MapDefectOptions defects;
  /// Beyond the thesis: the relaxation of the domain, on by default (as rigid as possible,
  /// robust); iterations 0 gives the thesis' map.
  RelaxationOptions relaxation;
  /// The share of points flagged (folds plus overlaps) above which the map is reported as not
  /// one-to-one (the target for genus-0 surfaces: below 0.1%).
  double maxDefectFraction = 0.001;
  /// A point is valid when its fit failed at no more than this share of the steps.
  double maxFailedStepFraction = 0.1;
};

struct Parametrization {
  FlatteningResult flattening;
  DomainMap domain;
  MapDefects defects;
  RelaxationResult relaxation;
  std::vector<std::uint8_t> valid;  // per point
  std::size_t invalid = 0;
  bool oneToOne = true;  // defects below maxDefectFraction
  std::vector<std::string> warnings;
};

/// Parametrizes a cloud with oriented unit normals. Throws OptionError on invalid options or
/// inputs, Cancelled through `progress`. Identical results for any thread count.
Parametrization parametrize(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                            const ParametrizationOptions& options = {},
                            const ProgressCallback& progress = {});

}  // namespace scalespace
