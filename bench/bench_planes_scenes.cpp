// Plane detection on scenes built like real buildings (core/SceneGenerator.hpp: house, yard; Stairs
// of Table 2.1 for reference) at noise 0 and 2.5e-4 of the diagonal (the largest level of
// Fig. 2.14), for our persistence pipeline with the defaults of `scalespace planes` (robust APSS
// stack, Sec. 2.3; M scales; theta = 5 degrees) and CGAL Efficient RANSAC in the same run.
// Per scene and noise level:
// - faces: the ground-truth faces at least 3 t_min wide, t_min = t_1 of our series (Sec. 1.5.1),
//   a face's width being its smaller extent along the principal in-plane axes of its area. A face
//   is found when some point set has IoU >= 0.8 with it. "region": some region of some scale (the
//   filtered regions of Sec. 2.3.1; what `segment --scale T` shows); "comp": the region of some
//   component of persistence >= P at its representative level (Sec. 2.3.3; the level its plane,
//   area and outline come from); "seg": the labels of `segment --min-persistence P` (Sec. 2.4.1).
// - tops: raised tile tops found as regions of some scale (house: 24 tiles 2.5 cm proud).
// - groups (gt_group; on Stairs every point is the ramp): the best IoU of any region of any scale
//   with the group's points, and that scale.
// - rms/t: per component reported as a plane (flagged planar with the planarity split; every
//   component without it), the RMS point-to-plane distance of its plane at its representative
//   level over that level's scale t: the worst, and how many exceed 5 % (the noise floor of the
//   flag allows it below 40 sigma); the largest such component (points at its representative
//   level) and its rms/t. The comment line counts the flagged components and gives the noise the
//   flag allowed for against the true sigma.
// RANSAC (epsilon 2.5e-4 of the diagonal plus 3 noise sigmas, i.e. 4.5 mm on the noise-free house;
// cluster epsilon 2 t_min; min points n/10000; CGAL's other defaults) has one level: its planes are
// its regions, components and segmentation; its rms column is relative to epsilon. Usage:
// bench_planes_scenes [--points N (300000)] [--scales M (50)] [--scene house|yard|stairs]
//                            [--noise X] [--min-persistence P (5)] [--no-ransac] [--diagnose]
//                            [--max-step F] [--max-rms F] [--merge-rms F] [--merge-deviation F]
//                            [--merge-parallel DEG]
//                            [--merge-width F] [--refine-distance F] [--refine-gain F]
//                            [--no-refine-unlabelled] [--fill-max-angle DEG]
//                            [--refine-offset F] [--planar-noise F]
//                            (PlaneDetectionOptions; default: the library's)
//                            [--no-robust] (the plain APSS stack)
// --diagnose also prints, per group and level, the region holding most of the group; per level
// the tile tops found and where their points went; the faces of the largest component along its
// life; the counted faces not found.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "BenchMain.hpp"
#include "RansacPeer.hpp"
#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/planes/AlphaShapeArea.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/planes/StackPlanes.hpp"

using namespace scalespace;

namespace {

constexpr double kMatchIoU = 0.8;     // a face or group is found at IoU >= 0.8 (issue's criterion)
constexpr double kWidthInTMin = 3.0;  // faces narrower than 3 t_min are not counted
constexpr double kMaxRmsOverT = 0.05;

// Smaller extent of a face along the principal axes of its area in its plane: the short side of
// a rectangle. A triangle's second moment is area/12 (sum v v^T + s s^T), s = sum of its vertices.
double faceWidth(const SceneFace& face) {
  Vec3 first = Vec3::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  double area = 0;
  for (std::size_t t = 0; t + 2 < face.triangles.size(); t += 3) {
    const Vec3 &a = face.triangles[t], &b = face.triangles[t + 1], &c = face.triangles[t + 2];
    const double w = 0.5 * (b - a).cross(c - a).norm();
    const Vec3 s = a + b + c;
    first += w / 3 * s;
    second +=
        w / 12 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
    area += w;
  }
  const Vec3 mean = first / area;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(second / area - mean * mean.transpose());
  double width = 1e300;
  for (int axis = 1; axis < 3; ++axis) {  // the two largest: in the plane
    double lo = 1e300, hi = -1e300;
    for (const Vec3& p : face.triangles) {
      const double x = p.dot(eig.eigenvectors().col(axis));
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    width = std::min(width, hi - lo);
  }
  return width;
}

struct Truth {
  std::vector<SceneFace> faces;
  std::vector<int> face, group;  // per point
  std::vector<std::size_t> faceSize, groupSize;
  std::vector<double> faceWidth;
  std::vector<std::string> groupNames;
  std::vector<int> tileTops;  // faces of group 0 parallel to its largest face, but that one
};

Truth makeTruth(SceneKind kind, const SceneOptions& options, const PointCloud& cloud) {
  Truth truth;
  truth.faces = sceneFaces(kind, options);
  truth.groupNames = sceneGroupNames(kind);
  for (double v : cloud.findAttribute("gt_face")->values) truth.face.push_back(int(v));
  if (const AttributeColumn* g = cloud.findAttribute("gt_group")) {
    for (double v : g->values) truth.group.push_back(int(v));
  } else if (kind == SceneKind::Stairs) {  // the whole scene is one staircase: its mean ramp
    truth.groupNames = {"staircase ramp"};
    truth.group.assign(cloud.size(), 0);
  } else {
    truth.group.assign(cloud.size(), -1);
  }
  truth.faceSize.assign(truth.faces.size(), 0);
  truth.groupSize.assign(truth.groupNames.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ++truth.faceSize[std::size_t(truth.face[i])];
    if (truth.group[i] >= 0) ++truth.groupSize[std::size_t(truth.group[i])];
  }
  for (const SceneFace& f : truth.faces) truth.faceWidth.push_back(faceWidth(f));
  if (kind == SceneKind::House) {
    const SceneFace* roof = nullptr;
    for (const SceneFace& f : truth.faces)
      if (f.group == 0 && (!roof || f.area() > roof->area())) roof = &f;
    for (const SceneFace& f : truth.faces)
      if (f.group == 0 && &f != roof && f.normal.dot(roof->normal) > 0.999)
        truth.tileTops.push_back(f.label);
  }
  return truth;
}

// Best IoU per face and per group over the point sets scored so far.
struct Best {
  std::vector<double> face, group, groupScale;
  std::vector<std::size_t> groupSetSize;
  Best(const Truth& truth)
      : face(truth.faces.size(), 0.0),
        group(truth.groupNames.size(), 0.0),
        groupScale(truth.groupNames.size(), 0.0),
        groupSetSize(truth.groupNames.size(), 0) {}
};

double iou(std::size_t common, std::size_t a, std::size_t b) {
  return double(common) / double(a + b - common);
}

// Scores one point set (a region, a component, a plane) against every face and group.
void score(const std::vector<Index>& points, const Truth& truth, double scale, Best& best) {
  std::map<int, std::size_t> faces, groups;
  for (Index i : points) {
    ++faces[truth.face[i]];
    if (truth.group[i] >= 0) ++groups[truth.group[i]];
  }
  for (const auto& [f, k] : faces)
    best.face[std::size_t(f)] =
        std::max(best.face[std::size_t(f)], iou(k, points.size(), truth.faceSize[std::size_t(f)]));
  for (const auto& [g, k] : groups) {
    const double v = iou(k, points.size(), truth.groupSize[std::size_t(g)]);
    if (v > best.group[std::size_t(g)]) {
      best.group[std::size_t(g)] = v;
      best.groupScale[std::size_t(g)] = scale;
      best.groupSetSize[std::size_t(g)] = points.size();
    }
  }
}

struct Recall {
  std::size_t counted = 0, found = 0, topsFound = 0;
};

Recall recall(const Best& best, const Truth& truth, double tMin) {
  Recall r;
  for (std::size_t f = 0; f < truth.faces.size(); ++f)
    if (truth.faceWidth[f] >= kWidthInTMin * tMin) {
      ++r.counted;
      r.found += best.face[f] >= kMatchIoU;
    }
  for (int f : truth.tileTops) r.topsFound += best.face[std::size_t(f)] >= kMatchIoU;
  return r;
}

std::string groupText(const Best& best, const Truth& truth) {
  std::string out;
  char buf[160];
  for (std::size_t g = 0; g < truth.groupNames.size(); ++g) {
    std::snprintf(buf, sizeof buf, "%s%s %.2f (t %.3g, %zu pts)", g ? "; " : "",
                  truth.groupNames[g].c_str(), best.group[g], best.groupScale[g],
                  best.groupSetSize[g]);
    out += buf;
  }
  return out;
}

std::vector<std::vector<Index>> setsOfLabels(const std::vector<int>& labels) {
  std::map<int, std::vector<Index>> sets;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] >= 0) sets[labels[i]].push_back(Index(i));
  std::vector<std::vector<Index>> out;
  for (auto& [label, pts] : sets) out.push_back(std::move(pts));
  return out;
}

void printRow(const char* scene, double noise, const char* method, const Truth& truth,
              const Recall& region, const Recall& comp, const Recall& seg, const Best& regionBest,
              double worstRms, std::size_t overRms, std::size_t sets, std::size_t largest,
              double largestRms, double seconds) {
  char tops[32] = "-";
  if (!truth.tileTops.empty())
    std::snprintf(tops, sizeof tops, "%zu/%zu", region.topsFound, truth.tileTops.size());
  std::printf(
      "%-6s %-7g %-6s %5zu %6.1f%% %6.1f%% %6.1f%% %6s %7.1f%% %5zu %6zu %8zu %7.1f%% %8.2f  %s\n",
      scene, noise, method, region.counted, 100.0 * double(region.found) / double(region.counted),
      100.0 * double(comp.found) / double(comp.counted),
      100.0 * double(seg.found) / double(seg.counted), tops, 100 * worstRms, overRms, sets, largest,
      100 * largestRms, seconds, groupText(regionBest, truth).c_str());
  std::fflush(stdout);
}

// The three largest faces among `points`, as "label(nx,ny,nz):count".
std::string composition(const std::vector<Index>& points, const Truth& truth) {
  std::map<int, std::size_t> faces;
  for (Index i : points) ++faces[truth.face[i]];
  std::vector<std::pair<std::size_t, int>> byCount;
  for (const auto& [f, k] : faces) byCount.emplace_back(k, f);
  std::sort(byCount.rbegin(), byCount.rend());
  std::string out;
  char buf[96];
  for (std::size_t k = 0; k < std::min<std::size_t>(3, byCount.size()); ++k) {
    const SceneFace& f = truth.faces[std::size_t(byCount[k].second)];
    std::snprintf(buf, sizeof buf, "%s f%d(%.2f,%.2f,%.2f) %zu/%zu", k ? ", " : "", f.label,
                  f.normal.x(), f.normal.y(), f.normal.z(), byCount[k].first,
                  truth.faceSize[std::size_t(f.label)]);
    out += buf;
  }
  return out;
}

// The counted faces that no point set matched, with their best IoU.
void printMissedFaces(const Truth& truth, const Best& best, double tMin) {
  std::printf("# counted faces not found: label (normal) width area best-IoU\n");
  for (std::size_t f = 0; f < truth.faces.size(); ++f)
    if (truth.faceWidth[f] >= kWidthInTMin * tMin && best.face[f] < kMatchIoU)
      std::printf("#   f%zu (%.2f,%.2f,%.2f) %.3f m %.3f m2 IoU %.2f\n", f,
                  truth.faces[f].normal.x(), truth.faces[f].normal.y(), truth.faces[f].normal.z(),
                  truth.faceWidth[f], truth.faces[f].area(), best.face[f]);
}

void diagnose(const PointCloud& cloud, const PlaneDetection& detection, const PlaneModel& model,
              const Truth& truth) {
  const RegionGraph& graph = detection.graph;
  for (std::size_t g = 0; g < truth.groupNames.size(); ++g) {
    // The group's faces parallel to its largest one (treads; roof and tile tops) and the others
    // (risers; tile sides): which of them the region holding most of the group takes.
    // Stairs: no face has a group, every face is the ramp's.
    const bool labelled = std::any_of(truth.faces.begin(), truth.faces.end(),
                                      [&](const SceneFace& f) { return f.group == int(g); });
    const SceneFace* main = nullptr;
    for (const SceneFace& f : truth.faces)
      if ((!labelled || f.group == int(g)) && (!main || f.area() > main->area())) main = &f;
    const auto parallel = [&](Index i) {
      return truth.faces[std::size_t(truth.face[i])].normal.dot(main->normal) > 0.999;
    };
    std::size_t parallelSize = 0;
    for (std::size_t i = 0; i < truth.group.size(); ++i)
      parallelSize += truth.group[i] == int(g) && parallel(Index(i));
    std::printf("# group '%s' (%zu points): per level, the region holding most of it\n",
                truth.groupNames[g].c_str(), truth.groupSize[g]);
    for (int l = 0; l < model.scaleCount(); ++l) {
      std::size_t bestCommon = 0, bestRegion = 0;
      const auto& regions = graph.levels[std::size_t(l)].regions;
      for (std::size_t r = 0; r < regions.size(); ++r) {
        std::size_t k = 0;
        for (Index i : regions[r]) k += truth.group[i] == int(g);
        if (k > bestCommon) bestCommon = k, bestRegion = r;
      }
      if (bestCommon == 0) {
        std::printf("#   l %2d t %.4g: none\n", l, model.scales[std::size_t(l)]);
        continue;
      }
      const auto& pts = regions[bestRegion];
      std::size_t inParallel = 0;
      std::vector<Index> outside;
      for (Index i : pts) {
        inParallel += truth.group[i] == int(g) && parallel(i);
        if (truth.group[i] != int(g)) outside.push_back(i);
      }
      std::printf(
          "#   l %2d t %.4g: region %zu pts (comp %d), holds %.2f of the group (%zu/%zu of its "
          "faces parallel to the largest, %zu/%zu of the others), %.2f of it in the group, IoU "
          "%.2f; %s; outside the group: %s\n",
          l, model.scales[std::size_t(l)], pts.size(),
          graph.componentOf[std::size_t(l)][bestRegion],
          double(bestCommon) / double(truth.groupSize[g]), inParallel, parallelSize,
          bestCommon - inParallel, truth.groupSize[g] - parallelSize,
          double(bestCommon) / double(pts.size()), iou(bestCommon, pts.size(), truth.groupSize[g]),
          composition(pts, truth).c_str(), composition(outside, truth).c_str());
      // Where the rest of the group is: the next regions holding most of it, and unlabelled.
      std::map<int, std::size_t> holders;
      std::vector<Index> unlabelled;
      std::vector<int> labels(truth.group.size(), -1);
      for (std::size_t r = 0; r < regions.size(); ++r)
        for (Index i : regions[r]) labels[i] = int(r);
      for (std::size_t i = 0; i < truth.group.size(); ++i)
        if (truth.group[i] == int(g)) {
          if (labels[i] < 0)
            unlabelled.push_back(Index(i));
          else if (std::size_t(labels[i]) != bestRegion)
            ++holders[labels[i]];
        }
      std::vector<std::pair<std::size_t, int>> byCount;
      for (const auto& [r, k] : holders) byCount.emplace_back(k, r);
      std::sort(byCount.rbegin(), byCount.rend());
      std::printf("#        unlabelled %zu (%s); other regions (group points / size):",
                  unlabelled.size(), composition(unlabelled, truth).c_str());
      for (std::size_t k = 0; k < std::min<std::size_t>(5, byCount.size()); ++k)
        std::printf(" %zu/%zu", byCount[k].first, regions[std::size_t(byCount[k].second)].size());
      std::printf("\n");
    }
  }
  if (!truth.tileTops.empty()) {
    std::vector<bool> isTop(truth.faces.size(), false);
    std::size_t topPoints = 0;
    for (int f : truth.tileTops) {
      isTop[std::size_t(f)] = true;
      topPoints += truth.faceSize[std::size_t(f)];
    }
    std::printf(
        "# tile tops: per level, tops found (IoU >= 0.8), share of top points in some region, in "
        "a region of > 1000 points, and the sizes of the regions mostly made of top points\n");
    for (int l = 0; l < model.scaleCount(); ++l) {
      std::vector<double> topBest(truth.faces.size(), 0);
      std::size_t inRegion = 0, inLarge = 0;
      std::vector<std::size_t> topRegionSizes;
      for (const std::vector<Index>& r : graph.levels[std::size_t(l)].regions) {
        std::map<int, std::size_t> faces;
        std::size_t tops = 0;
        for (Index i : r)
          if (isTop[std::size_t(truth.face[i])]) ++faces[truth.face[i]], ++tops;
        inRegion += tops;
        if (r.size() > 1000) inLarge += tops;
        if (2 * tops > r.size()) topRegionSizes.push_back(r.size());
        for (const auto& [f, k] : faces)
          topBest[std::size_t(f)] =
              std::max(topBest[std::size_t(f)], iou(k, r.size(), truth.faceSize[std::size_t(f)]));
      }
      std::size_t found = 0;
      for (int f : truth.tileTops) found += topBest[std::size_t(f)] >= kMatchIoU;
      std::sort(topRegionSizes.begin(), topRegionSizes.end());
      std::string sizes;
      for (std::size_t s : topRegionSizes) sizes += " " + std::to_string(s);
      std::printf(
          "#   l %2d t %.4g: %zu found, %.2f in regions, %.2f in large ones; top regions:%s\n", l,
          model.scales[std::size_t(l)], found, double(inRegion) / double(topPoints),
          double(inLarge) / double(topPoints), sizes.c_str());
    }
  }
  std::size_t largest = 0;
  for (std::size_t c = 0; c < model.components.size(); ++c)
    if (model.components[c].pointCount > model.components[largest].pointCount) largest = c;
  if (!model.components.empty()) {
    const PlaneComponent& c = model.components[largest];
    std::printf("# largest component %zu: levels %d-%d, representative %d, rms/t %.3f\n", largest,
                c.birthLevel, c.deathLevel, c.representativeLevel,
                c.plane.rms / model.scales[std::size_t(c.representativeLevel)]);
    std::printf(
        "#   per level: points, Jaccard index with the previous level's region, highest point on "
        "a vertical face (m above the ground), main faces\n");
    for (int l = c.birthLevel; l <= c.deathLevel; ++l) {
      const auto& pts = componentPointsAt(graph, int(largest), l);
      const double jaccard =
          l > c.birthLevel ? jaccardIndex(componentPointsAt(graph, int(largest), l - 1), pts) : 1.0;
      double zVertical = 0;
      for (Index i : pts)
        if (std::abs(truth.faces[std::size_t(truth.face[i])].normal.z()) < 0.1)
          zVertical = std::max(zVertical, cloud.absolutePosition(i).z());
      std::printf("#   l %2d t %.4g: %zu pts, J %.2f, z %.2f; %s\n", l,
                  model.scales[std::size_t(l)], pts.size(), jaccard, zVertical,
                  composition(pts, truth).c_str());
    }
  }
}

// Our pipeline with the defaults of `scalespace planes` (and the detection options given).
void runOurs(const PointCloud& cloud, const Truth& truth, const char* scene, double noise,
             int scales, int minPersistence, bool diagnostics, double& tMinOut,
             const PlaneDetectionOptions& options, bool robust) {
  ScaleSpaceOptions stack;
  stack.fit.robust = robust;  // Sec. 2.3, Fig. 2.5: planes use the robust APSS
  stack.series.count = scales;
  const StackPlaneDetection result = detectPlanesInCloud(cloud, stack, options);
  const PlaneDetection& detection = result.detection;
  const PlaneModel model = makePlaneModel(detection);
  const double tMin = model.scales.front();
  tMinOut = tMin;

  Best regionBest(truth), compBest(truth), segBest(truth);
  for (int l = 0; l < detection.scaleCount(); ++l)
    for (const std::vector<Index>& r : detection.graph.levels[std::size_t(l)].regions)
      score(r, truth, model.scales[std::size_t(l)], regionBest);
  // The rms columns are over the components a user is told are planes: with the planarity split
  // the flagged ones (PlaneComponent::planar false) are counted apart; the thesis' graph
  // (--max-rms 0) reports every component.
  double worstRms = 0, largestRms = 0;
  std::size_t overRms = 0, overRmsAboveNoise = 0, overRmsUnmarked = 0, largest = 0, flagged = 0;
  const double sigma = noise * cloud.boundingBoxDiagonal();
  for (const PlaneComponent& c : model.components) {
    const double t = model.scales[std::size_t(c.representativeLevel)];
    if (c.persistence >= minPersistence)
      score(componentPointsAt(detection.graph, c.id, c.representativeLevel), truth, t, compBest);
    const double rel = c.plane.valid ? c.plane.rms / t : 0.0;
    if (model.planaritySplit && !c.planar) {
      ++flagged;
      continue;
    }
    worstRms = std::max(worstRms, rel);
    overRms += rel > kMaxRmsOverT;
    // Noise alone gives rms/t = sigma/t: above 5 % for t < 20 sigma, whatever the plane.
    overRmsAboveNoise += rel > kMaxRmsOverT && t >= sigma / kMaxRmsOverT;
    overRmsUnmarked += rel > kMaxRmsOverT && !c.noiseLimited;
    if (c.pointCount > largest) largest = c.pointCount, largestRms = rel;
  }
  for (const auto& set : setsOfLabels(labelsByPersistence(model, minPersistence)))
    score(set, truth, 0, segBest);
  printRow(scene, noise, "ours", truth, recall(regionBest, truth, tMin),
           recall(compBest, truth, tMin), recall(segBest, truth, tMin), regionBest, worstRms,
           overRms, model.components.size(), largest, largestRms, result.totalSeconds);
  std::printf(
      "#   t_min %.4g (3 t_min %.4g), t_max %.4g; planar components with rms/t > 5 %%: %zu, %zu "
      "of them at t >= 20 sigma, %zu not marked noise_limited; flagged non-planar: %zu; noise: "
      "estimated %.3g, true sigma %.3g; "
      "time: stack %.2f s, knn %.2f s, segmentation %.2f s, filtering %.2f s "
      "(both during the stack; %.2f s after it), graph %.3f s, components %.2f s\n",
      tMin, kWidthInTMin * tMin, model.scales.back(), overRms, overRmsAboveNoise, overRmsUnmarked,
      flagged, detection.noiseRms, sigma, result.stackSeconds, result.knnSeconds,
      detection.timings.segmentation, detection.timings.filtering, result.segmentationWaitSeconds,
      detection.timings.graph, detection.timings.components);
  if (!diagnostics) return;
  diagnose(cloud, detection, model, truth);
  std::printf(
      "# planar components with rms/t > 5 %% at t >= 20 sigma: id, level, t, rms/sigma, "
      "points, the faces holding most of them (label: share)\n");
  for (const PlaneComponent& c : model.components) {
    const double t = model.scales[std::size_t(c.representativeLevel)];
    if (!c.plane.valid || (model.planaritySplit && !c.planar)) continue;
    if (c.plane.rms / t <= kMaxRmsOverT || t < sigma / kMaxRmsOverT) continue;
    std::map<int, std::size_t> faces;
    const std::vector<Index>& pts = componentPointsAt(detection.graph, c.id, c.representativeLevel);
    for (Index i : pts) ++faces[truth.face[i]];
    std::vector<std::pair<std::size_t, int>> sorted;
    for (const auto& [f, k] : faces) sorted.push_back({k, f});
    std::sort(sorted.rbegin(), sorted.rend());
    std::printf("#   %d l %d t %.4g rms/t %.3f rms/sigma %.2f n %zu:", c.id, c.representativeLevel,
                t, c.plane.rms / t, c.plane.rms / sigma, pts.size());
    for (std::size_t k = 0; k < std::min<std::size_t>(4, sorted.size()); ++k)
      std::printf(" %d(g%d): %.2f", sorted[k].second,
                  truth.faces[std::size_t(sorted[k].second)].group,
                  double(sorted[k].first) / double(pts.size()));
    std::printf("\n");
  }
  std::printf("# as regions of any scale:\n");
  printMissedFaces(truth, regionBest, tMin);
  std::printf("# as components of persistence >= %d at their representative level:\n",
              minPersistence);
  printMissedFaces(truth, compBest, tMin);
  std::printf("# as labels of segment --min-persistence %d:\n", minPersistence);
  printMissedFaces(truth, segBest, tMin);
  std::fflush(stdout);
}

void runPeer(const PointCloud& cloud, const Truth& truth, const char* scene, double noise,
             double tMin, bool diagnostics) {
  const double diagonal = cloud.boundingBoxDiagonal();
  bench::RansacSettings settings;
  // The scene's sigma is noise * diagonal (SceneOptions::noise): 3 sigma hold 99.7 % of a plane.
  settings.epsilon = 2.5e-4 * diagonal + 3 * noise * diagonal;
  // Cluster epsilon 2 t_min (t_min: the median 10-NN radius, a property of the sampling): a
  // sampled face stays one cluster, coplanar faces apart by more (the tile tops) do not.
  settings.clusterEpsilon = 2 * tMin;
  settings.minPoints = std::max<std::size_t>(10, cloud.size() / 10000);
  const bench::Detection d = bench::runRansac(cloud, settings);
  Best best(truth);
  double worstRms = 0, largestRms = 0;
  std::size_t overRms = 0, largest = 0;
  for (const auto& plane : d.planes) {
    score(plane, truth, 0, best);
    const PlaneFit fit = fitPlane(cloud.positions(), plane);
    const double rel = fit.valid ? fit.rms / settings.epsilon : 0.0;
    worstRms = std::max(worstRms, rel);
    overRms += rel > 1;
    if (plane.size() > largest) largest = plane.size(), largestRms = rel;
  }
  const Recall r = recall(best, truth, tMin);
  printRow(scene, noise, "ransac", truth, r, r, r, best, worstRms, overRms, d.planes.size(),
           largest, largestRms, d.seconds);
  std::printf("#   epsilon %.4g, min points %zu\n", settings.epsilon, settings.minPoints);
  if (diagnostics) printMissedFaces(truth, best, tMin);
}

}  // namespace

static int run(int argc, char** argv) {
  scalespace::retainFreedMemory();  // as the CLI does (core/MemoryReuse.hpp)
  std::size_t points = 300000;
  int scales = 50, minPersistence = 5;
  double onlyNoise = -1;
  std::string onlyScene;
  bool peers = true, diagnostics = false, robust = true;
  PlaneDetectionOptions detection;
  const std::vector<double> noiseLevels{0.0, 2.5e-4};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--points" && hasValue) {
      points = scalespace::bench::countArgument(argv, ++i);
    } else if (a == "--scales" && hasValue) {
      scales = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--scene" && hasValue) {
      onlyScene = argv[++i];
    } else if (a == "--noise" && hasValue) {
      onlyNoise = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--min-persistence" && hasValue) {
      minPersistence = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--max-step" && hasValue) {
      detection.growing.maxStep = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--merge-rms" && hasValue) {
      detection.merging.maxRelativeRms = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--no-refine-unlabelled") {
      detection.refinement.takeUnlabelled = false;
    } else if (a == "--fill-max-angle" && hasValue) {
      detection.refinement.fillMaxAngleDegrees = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--refine-distance" && hasValue) {
      detection.refinement.maxRelativeDistance = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--planar-noise" && hasValue) {
      detection.planarity.noiseFactor = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--refine-gain" && hasValue) {
      detection.refinement.minRelativeGain = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--refine-offset" && hasValue) {
      detection.refinement.minRelativeOffset = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--merge-width" && hasValue) {
      detection.merging.minRelativeWidth = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--merge-parallel" && hasValue) {
      detection.merging.parallelDegrees = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--merge-deviation" && hasValue) {
      detection.merging.maxRelativeDeviation = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--max-rms" && hasValue) {
      detection.planarity.maxRelativeRms = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--no-robust") {
      robust = false;
    } else if (a == "--no-ransac") {
      peers = false;
    } else if (a == "--diagnose") {
      diagnostics = true;
    } else {
      std::fprintf(stderr, "bench_planes_scenes: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  std::printf(
      "# %zu points, %d scales; faces found at IoU >= %.1f among faces >= %.0f t_min wide; "
      "components of persistence >= %d for comp / seg; rms: ours rms/t at the representative "
      "level (count > 5 %%), ransac rms/epsilon (count > 1)\n",
      points, scales, kMatchIoU, kWidthInTMin, minPersistence);
  std::printf("%-6s %-7s %-6s %5s %7s %7s %7s %6s %8s %5s %6s %8s %8s %8s  %s\n", "scene", "noise",
              "method", "faces", "region", "comp", "seg", "tops", "rms_max", "n>", "comps",
              "largest", "lrg_rms", "seconds", "groups: best IoU (scale, points)");
  for (SceneKind kind : {SceneKind::House, SceneKind::Yard, SceneKind::Stairs}) {
    if (!onlyScene.empty() && onlyScene != sceneKindName(kind)) continue;
    for (double noise : onlyNoise >= 0 ? std::vector<double>{onlyNoise} : noiseLevels) {
      SceneOptions options;
      options.pointCount = points;
      options.noise = noise;
      const PointCloud cloud = generateScene(kind, options);
      const Truth truth = makeTruth(kind, options, cloud);
      double tMin = 0;
      runOurs(cloud, truth, sceneKindName(kind), noise, scales, minPersistence, diagnostics, tMin,
              detection, robust);
      if (peers) runPeer(cloud, truth, sceneKindName(kind), noise, tMin, diagnostics);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_planes_scenes", [&] { return run(argc, argv); });
}
