#include "scalespace/param/Parametrization.hpp"

#include <cmath>
#include <cstdio>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"

namespace scalespace {
namespace {

std::string percent(std::size_t part, std::size_t whole) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g%%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return text;
}

}  // namespace

Parametrization parametrize(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                            const ParametrizationOptions& options,
                            const ProgressCallback& progress) {
  if (!(options.maxDefectFraction >= 0 && options.maxDefectFraction <= 1))
    throw OptionError("ParametrizationOptions::maxDefectFraction must be in [0, 1]");
  if (!(options.maxFailedStepFraction >= 0 && options.maxFailedStepFraction <= 1))
    throw OptionError("ParametrizationOptions::maxFailedStepFraction must be in [0, 1]");
  validateMapDefectOptions(options.defects);
  validateRelaxationOptions(options.relaxation);
  ThreadLimit limit(options.flattening.threads);
  Parametrization result;
  const bool relax = options.relaxation.iterations > 0;
  result.flattening = flattenScaleSpace(positions, normals, options.flattening,
                                        subProgress(progress, 0, relax ? 0.75 : 0.9));
  result.domain = mapToDomain(result.flattening, options.domain);
  result.warnings = result.domain.warnings;
  if (relax) {
    RelaxationOptions relaxation = options.relaxation;
    relaxation.defects = options.defects;
    result.relaxation = relaxConformally(positions, normals, result.domain, relaxation,
                                         subProgress(progress, 0.75, 1));
    // A large sphere domain is left as the thesis maps it unless asked, said in the JSON, not
    // warned about.
    const bool largeSphere = result.domain.kind == DomainKind::Sphere &&
                             positions.size() > relaxation.maxSolvePoints &&
                             !relaxation.largeSpheres;
    if (!result.relaxation.applied && !largeSphere)
      result.warnings.push_back("relaxation not applied: " + result.relaxation.reason);
    else if (result.relaxation.applied && result.relaxation.roundsApplied < relaxation.rounds)
      result.warnings.push_back(
          "the relaxation's robust rounds would add folds or overlaps: one plain round applied");
  }
  // The relaxation checked the map it leaves (unless it could not run).
  if (!result.relaxation.defects.fold.empty())
    result.defects = std::move(result.relaxation.defects);
  else
    result.defects = findMapDefects(positions, normals, result.domain, options.defects,
                                    subProgress(progress, relax ? 0.75 : 0.9, 1));

  const std::size_t n = positions.size();
  const double maxFailed = options.maxFailedStepFraction * options.flattening.scaleCount;
  result.valid.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    result.valid[i] = result.flattening.failedSteps[i] <= maxFailed;
    result.invalid += !result.valid[i];
  }
  if (result.invalid > 0)
    result.warnings.push_back(
        std::to_string(result.invalid) + " points (" + percent(result.invalid, n) +
        ") had no valid fit at more than " +
        percent(std::size_t(std::lround(100 * options.maxFailedStepFraction)), 100) +
        " of the scales: isolated or duplicate points (column param_valid)");
  const std::size_t flagged = result.defects.folds + result.defects.overlaps;
  result.oneToOne = double(flagged) <= options.maxDefectFraction * double(n);
  if (!result.oneToOne)
    result.warnings.push_back(
        "the map is not one-to-one: " + std::to_string(result.defects.folds) + " points fold (" +
        percent(result.defects.folds, n) + ") and " + std::to_string(result.defects.overlaps) +
        " overlap (" + percent(result.defects.overlaps, n) +
        "). A surface that is not of genus 0 (a torus, a handle), several separate surfaces (a "
        "table above a floor) or thin parts the flow squashed together (legs) cannot be "
        "flattened one-to-one (columns fold and overlap)");
  return result;
}

}  // namespace scalespace
