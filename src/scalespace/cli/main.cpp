// scalespace: command-line front end. Each group of commands lives in its own file and registers
// itself on the CLI11 app; this file only dispatches and turns exceptions into one-line errors.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <utility>

#include "scalespace/cli/CloudCommands.hpp"
#include "scalespace/cli/ProgressBar.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/MemoryReuse.hpp"

namespace {

// The library's messages name its option fields (a Python or C++ caller has no flags); a CLI user
// reads the flags that set them.
const std::pair<const char*, const char*> kFlagOfOption[] = {
    {"ReadOptions::dropNonFinite", "--drop-invalid"},
    {"NormalEstimationOptions::k", "--k"},
    {"NormalOrientationOptions::k", "--k"},
    {"CurvatureOptions::scaleK", "--scale-k"},
    {"CurvatureOptions::scale", "--scale"},
    {"ScaleSeriesOptions::count", "--scales"},
    {"CoverageOptions::maxDistanceFraction", "--coverage-distance"},
    {"CoverageOptions::maxAngleDegrees", "--coverage-angle"},
    {"SimilarityOptions::birthTolerance", "--birth-tolerance"},
    {"SimilarityOptions::deathTolerance", "--death-tolerance"},
    {"SimilarityOptions::maxAreaDifference", "--area-tolerance"},
    {"SimilarityOptions::maxAngleDegrees", "--angle"},
    {"ScaleSeriesOptions::spacing", "--spacing"},
    {"ScaleSeriesOptions::tMin", "--tmin"},
    {"ScaleSeriesOptions::tMax", "--tmax"},
    {"FitOptions::mlsMaxSteps", "--mls-steps"},
    {"ScaleSpaceOptions::alpha", "--alpha"},
    {"RegionGrowingOptions::maxStep", "--max-step"},
    {"PlanarityOptions::maxRelativeRms", "--max-rms"},
    {"RegionMergeOptions::maxRelativeRms", "--merge-rms"},
    {"RegionMergeOptions::maxRelativeDeviation", "--merge-deviation"},
    {"RegionMergeOptions::parallelDegrees", "--merge-parallel"},
    {"BoundaryRefinementOptions::maxRelativeDistance", "--refine-distance"},
    {"RegionGrowingOptions::maxAngleDegrees", "--angle"},
    {"StackWriteOptions::encoding", "--encoding"},
    {"RenderOptions::up", "--up"},
    {"RenderOptions::view", "--view"},
    {"RenderOptions::checkerCells", "--checker-cells"},
    {"RenderOptions::checkerAttributes", "--checker"},
    {"LineRenderOptions::colorAttribute", "--line-color-by"},
    {"RenderOptions::width and height", "--size width and height"},
    {"SceneOptions::noise", "--noise"},
    {"CurvatureLineOptions::beta", "--beta"},
    {"CurvatureLineOptions::gamma", "--gamma"},
    {"CurvatureLineOptions::alpha", "--alpha"},
    {"CurvatureLineOptions::maxSteps", "--max-steps"},
    {"FeatureCurveOptions::spacing", "--spacing"},
    {"FeatureCurveOptions::scaleCount", "--scales"},
    {"FeatureCurveOptions::salientThreshold", "--salient"},
    {"FeatureCurveOptions::salientBoundCap", "--salient-cap"},
    {"FeatureCurveOptions::voteThreshold", "--vote-threshold"},
    {"FeatureCurveOptions::spacing", "--spacing"},
    {"FeatureCurveOptions::minCurveExtent", "--min-extent"},
    {"FeatureCurveOptions::foldReach", "--fold-reach"},
    {"FeatureCurveOptions::foldBorderShare", "--fold-share"},
    {"FeatureCurveOptions::edgeReach", "--edge-reach"},
    {"FeatureCurveOptions::edgeRejoinAngle", "--edge-rejoin-angle"},
    {"FeatureCurveOptions::joinGap", "--join-gap"},
    {"FeatureCurveOptions::minSalientCurvature", "--min-curvature"},
    {"FeatureCurveOptions::minVotingScales", "--min-scales"},
    {"FeatureCurveOptions::noiseSalientFactor", "--noise-curvature"},
    {"FeatureCurveOptions::centrelineReach", "--centreline-reach"},
    {"FeatureCurveOptions::bandHalfWidth", "--band-half-width"},
    {"FeatureCurveOptions::creaseReach", "--crease-reach"},
    {"FeatureCurveOptions::creaseHalfWidth", "--crease-half-width"},
    {"FeatureCurveOptions::creaseFlatness", "--crease-flatness"},
    {"FeatureCurveOptions::creaseSideMargin", "--crease-side-margin"},
    {"CylinderOptions::scaleCount", "--scales"},
    {"CylinderOptions::tMin", "--tmin"},
    {"CylinderOptions::tMax", "--tmax"},
    {"CylinderOptions::epsilon", "--epsilon"},
    {"CylinderOptions::minAnisotropy", "--min-anisotropy"},
    {"LineFilterOptions::minLengthFactor", "--min-line-length"},
    {"LineFilterOptions::maxCurvatureFactor", "--max-line-curvature"},
    {"LineFilterOptions::maxMeanVariation", "--max-line-variation"},
    {"TubeFitOptions::minArcDegrees", "--min-arc"},
    {"TubeFitOptions::minSectorFill", "--min-sector-fill"},
    {"TubeFitOptions::maxSectionShapeShare", "--max-section-shape"},
    {"TubeFitOptions::maxSectionShapeRms", "--max-section-shape-rms"},
    {"TubeFitOptions::maxFaceSectors", "--max-face-sectors"},
    {"TubeFitOptions::minFaceLeanDegrees", "--min-face-lean"},
    {"CylinderOptions::maxGapLevels", "--max-gap"},
    {"CylinderOptions::bridgeRadiusTolerance", "--bridge-radius-tolerance"},
    {"CylinderOptions::nestedLinkTolerance", "--nested-link-tolerance"},
    {"TubeTrimOptions::keepFraction", "--trim-keep-fraction"},
    {"TubeTrimOptions::minRadiusScales", "--trim-min-radius"},
    {"TubeTrimOptions::tubeMinAgainstShare", "--trim-against-share"},
    {"NarrowTubeOptions::minArcDegrees", "--narrow-min-arc"},
    {"NarrowTubeOptions::minPersistence", "--narrow-min-persistence"},
    {"NarrowTubeOptions::maxRadiusSpread", "--narrow-radius-spread"},
    {"TubeFitOptions::maxRelativeRms", "--max-rms"},
    {"FlatteningOptions::scaleCount", "--scales"},
    {"FlatteningOptions::K", "--k"},
    {"FlatteningOptions::tMax", "--tmax"},
    {"DistortionOptions::neighbors", "--scales-k"},
    {"RelaxationOptions::iterations", "--relax"},
    {"RelaxationOptions::rounds", "--relax-rounds"},
    {"the thread count (threads option)", "--threads"},
    {"findSimilar: no component", "--similar: no component"},
};

std::string withFlags(std::string message) {
  for (const auto& [option, flag] : kFlagOfOption)
    for (std::size_t at = message.find(option); at != std::string::npos;
         at = message.find(option, at + std::strlen(flag)))
      message.replace(at, std::strlen(option), flag);
  return message;
}

}  // namespace

int main(int argc, char** argv) {
  scalespace::retainFreedMemory();  // per-scale arrays reuse memory (core/MemoryReuse.hpp)
  scalespace::cli::cancelOnInterrupt();
  CLI::App app{"scalespace " SCALESPACE_VERSION
               ": multi-scale analysis of 3D point clouds (normals, curvatures, scale spaces)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SCALESPACE_VERSION);
  scalespace::cli::addCloudCommands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, then a non-zero exit (CLI11's default prints two).
    std::fprintf(stderr, "scalespace: error: %s (see --help)\n", e.what());
    return 2;
  } catch (const scalespace::Cancelled& e) {
    std::fprintf(stderr, "scalespace: %s\n", e.what());
    return 130;
  } catch (const scalespace::OptionError& e) {
    std::fprintf(stderr, "scalespace: error: %s\n", withFlags(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scalespace: error: %s\n", withFlags(e.what()).c_str());
    return 1;
  }
  return 0;
}
