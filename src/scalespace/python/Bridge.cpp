#include "scalespace/python/Bridge.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/io/CloudBuilder.hpp"

namespace scalespace::python {
namespace {

// The library names its option fields (a C++ caller has no flags); a Python caller reads the
// keyword arguments that set them. The same fields as the CLI's table (cli/main.cpp).
const std::pair<const char*, const char*> kKeywordOfOption[] = {
    {"ReadOptions::dropNonFinite", "drop_invalid"},
    {"NormalEstimationOptions::k", "k"},
    {"NormalOrientationOptions::k", "k"},
    {"CurvatureOptions::scaleK", "scale_k"},
    {"CurvatureOptions::scale", "scale"},
    {"ScaleSeriesOptions::count", "scales"},
    {"CoverageOptions::maxDistanceFraction", "coverage_distance"},
    {"CoverageOptions::maxAngleDegrees", "coverage_angle"},
    {"SimilarityOptions::birthTolerance", "birth_tolerance"},
    {"SimilarityOptions::deathTolerance", "death_tolerance"},
    {"SimilarityOptions::maxAreaDifference", "area_tolerance"},
    {"SimilarityOptions::maxAngleDegrees", "angle"},
    {"ScaleSeriesOptions::spacing", "spacing"},
    {"ScaleSeriesOptions::tMin", "tmin"},
    {"ScaleSeriesOptions::tMax", "tmax"},
    {"FitOptions::mlsMaxSteps", "mls_steps"},
    {"ScaleSpaceOptions::alpha", "alpha"},
    {"RegionGrowingOptions::maxStep", "max_step"},
    {"PlanarityOptions::maxRelativeRms", "max_rms"},
    {"RegionMergeOptions::maxRelativeRms", "merge_rms"},
    {"RegionMergeOptions::maxRelativeDeviation", "merge_deviation"},
    {"RegionMergeOptions::parallelDegrees", "merge_parallel"},
    {"BoundaryRefinementOptions::maxRelativeDistance", "refine_distance"},
    {"BoundaryRefinementOptions::fillMaxAngleDegrees", "fill_max_angle"},
    {"NormalEstimationOptions::sheetTolerance", "sheet"},
    {"RegionGrowingOptions::maxAngleDegrees", "angle"},
    {"StackWriteOptions::encoding", "encoding"},
    {"RenderOptions::up", "up"},
    {"RenderOptions::view", "view"},
    {"RenderOptions::width and height", "width and height"},
    {"CurvatureLineOptions::beta", "beta"},
    {"CurvatureLineOptions::gamma", "gamma"},
    {"CurvatureLineOptions::alpha", "alpha"},
    {"CurvatureLineOptions::maxSteps", "max_steps"},
    {"FeatureCurveOptions::spacing", "spacing"},
    {"FeatureCurveOptions::scaleCount", "scales"},
    {"FeatureCurveOptions::salientThreshold", "salient_threshold"},
    {"FeatureCurveOptions::salientBoundCap", "salient_cap"},
    {"FeatureCurveOptions::voteThreshold", "vote_threshold"},
    {"FeatureCurveOptions::minCurveExtent", "min_extent"},
    {"FeatureCurveOptions::foldReach", "fold_reach"},
    {"FeatureCurveOptions::foldBorderShare", "fold_share"},
    {"FeatureCurveOptions::minPieceExtent", "min_piece_extent"},
    {"FeatureCurveOptions::joinGap", "join_gap"},
    {"FeatureCurveOptions::minSalientCurvature", "min_curvature"},
    {"FeatureCurveOptions::noiseSalientFactor", "noise_curvature"},
    {"FeatureCurveOptions::minVotingScales", "min_scales"},
    {"FeatureCurveOptions::centrelineReach", "centreline_reach"},
    {"FeatureCurveOptions::bandHalfWidth", "band_half_width"},
    {"FeatureCurveOptions::creaseReach", "crease_reach"},
    {"FeatureCurveOptions::creaseHalfWidth", "crease_half_width"},
    {"FeatureCurveOptions::creaseFlatness", "crease_flatness"},
    {"FeatureCurveOptions::creaseSideMargin", "crease_side_margin"},
    {"FeatureCurveOptions::edgeReach", "edge_reach"},
    {"FeatureCurveOptions::edgeRejoinAngle", "edge_rejoin_angle"},
    {"CylinderOptions::scaleCount", "scale_count"},
    {"CylinderOptions::scales", "scales"},
    {"CylinderOptions::tMin", "tmin"},
    {"CylinderOptions::tMax", "tmax"},
    {"CylinderOptions::epsilon", "epsilon"},
    {"FlatteningOptions::scaleCount", "scales"},
    {"FlatteningOptions::K", "k"},
    {"FlatteningOptions::tMax", "tmax"},
    {"DistortionOptions::neighbors", "scales_k"},
    {"RelaxationOptions::iterations", "relax"},
    {"RelaxationOptions::rounds", "relax_rounds"},
    {"RelaxationOptions::rigidity", "rigidity"},
    {"RelaxationOptions::sphereRigidity", "sphere_rigidity"},
    {"CylinderOptions::minAnisotropy", "min_anisotropy"},
    {"LineFilterOptions::minLengthFactor", "min_line_length"},
    {"LineFilterOptions::maxCurvatureFactor", "max_line_curvature"},
    {"LineFilterOptions::maxMeanVariation", "max_line_variation"},
    {"TubeFitOptions::minArcDegrees", "min_arc"},
    {"TubeFitOptions::minSectorFill", "min_sector_fill"},
    {"TubeFitOptions::maxSectionShapeShare", "max_section_shape"},
    {"TubeFitOptions::maxSectionShapeRms", "max_section_shape_rms"},
    {"TubeFitOptions::maxFaceSectors", "max_face_sectors"},
    {"TubeFitOptions::minFaceLeanDegrees", "min_face_lean"},
    {"CylinderOptions::maxGapLevels", "max_gap"},
    {"CylinderOptions::bridgeRadiusTolerance", "bridge_radius_tolerance"},
    {"CylinderOptions::nestedLinkTolerance", "nested_link_tolerance"},
    {"TubeTrimOptions::keepFraction", "trim_keep_fraction"},
    {"TubeTrimOptions::minRadiusScales", "trim_min_radius"},
    {"TubeTrimOptions::tubeMinAgainstShare", "trim_against_share"},
    {"NarrowTubeOptions::minArcDegrees", "narrow_min_arc"},
    {"NarrowTubeOptions::minPersistence", "narrow_min_persistence"},
    {"NarrowTubeOptions::maxRadiusSpread", "narrow_radius_spread"},
    {"TubeFitOptions::maxRelativeRms", "max_rms"},
    {"the thread count (threads option)", "threads"},
    {"findSimilar: no component", "similar: no component"},
};

PyObject* errorType = nullptr;
PyObject* optionErrorType = nullptr;
PyObject* fileErrorType = nullptr;
PyObject* cancelledType = nullptr;

std::thread::id mainThread;

PyObject* newException(py::module_& m, const char* name, PyObject* bases, const char* doc) {
  const std::string qualified = std::string("scalespace.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::handle(type));
  return type;
}

std::string dtypeName(const py::dtype& dtype) {
  return py::str(py::handle(dtype)).cast<std::string>();
}

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Any array-like as a float64 C-contiguous array: in place when it is one already.
DoubleArray asDoubles(const py::handle& object, const char* name, const char* expected) {
  const py::array any = py::module_::import("numpy").attr("asarray")(object);
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
    throwType(std::string(name) + ": expected " + expected + " of numbers, got dtype " +
              dtypeName(any.dtype()));
  return DoubleArray::ensure(any);
}

Points asRows(const py::handle& object, const char* name) {
  Points p;
  p.array = asDoubles(object, name, "a float64 array of shape (N, 3)");
  if (p.array.ndim() != 2 || p.array.shape(1) != 3)
    throwValue(std::string(name) + ": expected an array of shape (N, 3), got shape " +
               shapeText(p.array));
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");
  p.data = reinterpret_cast<const Vec3*>(p.array.data());
  p.size = std::size_t(p.array.shape(0));
  return p;
}

}  // namespace

std::string withKeywords(std::string message) {
  for (const auto& [option, keyword] : kKeywordOfOption)
    for (std::size_t at = message.find(option); at != std::string::npos;
         at = message.find(option, at + std::strlen(keyword)))
      message.replace(at, std::strlen(option), keyword);
  return message;
}

void registerErrors(py::module_& m) {
  errorType = newException(m, "Error", PyExc_RuntimeError, "Any error of the scalespace library.");
  optionErrorType = newException(
      m, "OptionError", py::make_tuple(py::handle(errorType), py::handle(PyExc_ValueError)).ptr(),
      "A bad argument: the message names it and the accepted values.");
  fileErrorType = newException(
      m, "FileError", py::make_tuple(py::handle(errorType), py::handle(PyExc_OSError)).ptr(),
      "A bad or unreadable file: FILE: WHERE: WHAT (FIX).");
  cancelledType = newException(m, "Cancelled", errorType,
                               "The progress callback returned False: nothing was written.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Cancelled& e) {
      PyErr_SetString(cancelledType, e.what());
    } catch (const OptionError& e) {
      PyErr_SetString(optionErrorType, withKeywords(e.what()).c_str());
    } catch (const FileError& e) {
      PyErr_SetString(fileErrorType, withKeywords(e.what()).c_str());
    } catch (const Error& e) {
      PyErr_SetString(errorType, withKeywords(e.what()).c_str());
    }
  });
}

void throwValue(const std::string& message) { throw py::value_error(message); }
void throwType(const std::string& message) { throw py::type_error(message); }

Points asPoints(const py::handle& object, const char* name) {
  Points p = asRows(object, name);
  if (p.size == 0)
    throwValue(std::string(name) + ": the array holds no points (nothing to analyse)");
  // The readers' policy (io/CloudBuilder.hpp) and wording, with the row for the place in the file.
  // The first unusable row, found in parallel blocks (a 1M-point check is a few ms alone), and in
  // the same pass the bounds that the cloud's origin comes from (exact: min and max in any order).
  struct Scan {
    std::size_t first;  // the first unusable row, or p.size
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
  };
  const Scan scan = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, p.size, std::size_t(1) << 15), Scan{p.size},
      [&](const tbb::blocked_range<std::size_t>& r, Scan s) {
        for (std::size_t j = r.begin(); j < std::min(r.end(), s.first); ++j) {
          if (!io_detail::isUsablePosition(p.data[j])) {
            s.first = j;
            break;
          }
          s.lo = s.lo.cwiseMin(p.data[j]);
          s.hi = s.hi.cwiseMax(p.data[j]);
        }
        return s;
      },
      [](Scan a, const Scan& b) {
        a.first = std::min(a.first, b.first);
        a.lo = a.lo.cwiseMin(b.lo);
        a.hi = a.hi.cwiseMax(b.hi);
        return a;
      });
  const std::size_t i = scan.first;
  if (i < p.size)
    throwValue(FileError(name, "row " + std::to_string(i),
                         "point " + std::to_string(i + 1) +
                             " has a NaN, infinite or absurdly large (beyond 1e100) coordinate",
                         "remove such rows, e.g. points[np.isfinite(points).all(axis=1)]")
                   .what());
  p.bounds = {scan.lo, scan.hi};
  return p;
}

Points asVectors(const py::handle& object, std::size_t rows, const char* name) {
  Points p = asRows(object, name);
  if (p.size != rows)
    throwValue(std::string(name) + ": expected " + std::to_string(rows) +
               " rows (one per point), got " + std::to_string(p.size));
  return p;
}

PooledCloud makeCloud(const Points& points, const py::handle& normals) {
  PooledCloud cloud = PooledCloud::fromPool();
  if (points.bounds)
    cloud.setAbsolutePositions(points.data, points.size, points.bounds->first,
                               points.bounds->second);
  else
    cloud.setAbsolutePositions(points.data, points.size);
  if (!normals.is_none()) {
    const Points n = asVectors(normals, points.size, "normals");
    cloud.setNormals(n.data, n.size);
  }
  return cloud;
}

std::vector<std::uint32_t> asIndices(const py::handle& object, const char* name,
                                     std::size_t limit) {
  const py::array any = py::module_::import("numpy").attr("asarray")(object);
  const char kind = any.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throwType(std::string(name) + ": expected integer point indices, got dtype " +
              dtypeName(any.dtype()));
  const auto values =
      py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(any);
  if (values.ndim() != 1)
    throwValue(std::string(name) + ": expected a 1-D array of point indices, got shape " +
               shapeText(values));
  std::vector<std::uint32_t> out(std::size_t(values.size()));
  for (std::size_t i = 0; i < out.size(); ++i) {
    const long long v = values.data()[i];
    if (v < 0 || std::size_t(v) >= limit)
      throwValue(std::string(name) + ": index " + std::to_string(v) + " is not a point (0.." +
                 std::to_string(limit) + ")");
    out[i] = std::uint32_t(v);
  }
  return out;
}

py::array_t<double> vectorsToArray(const std::vector<Vec3>& vectors, const Vec3& offset) {
  std::vector<double> flat(3 * vectors.size());
  for (std::size_t i = 0; i < vectors.size(); ++i)
    for (int c = 0; c < 3; ++c) flat[3 * i + std::size_t(c)] = vectors[i][c] + offset[c];
  return toArray(std::move(flat), {py::ssize_t(vectors.size()), 3});
}

namespace {
template <class T>
py::array typed(const std::vector<double>& values) {
  std::vector<T> out(values.begin(), values.end());
  return toArray(std::move(out));
}
}  // namespace

py::array columnToArray(AttributeColumn&& column, bool nativeType) {
  if (!nativeType || column.type == ScalarType::Float64) return toArray(std::move(column.values));
  switch (column.type) {
    case ScalarType::Int8:
      return typed<std::int8_t>(column.values);
    case ScalarType::UInt8:
      return typed<std::uint8_t>(column.values);
    case ScalarType::Int16:
      return typed<std::int16_t>(column.values);
    case ScalarType::UInt16:
      return typed<std::uint16_t>(column.values);
    case ScalarType::Int32:
      return typed<std::int32_t>(column.values);
    case ScalarType::UInt32:
      return typed<std::uint32_t>(column.values);
    case ScalarType::Float32:
      return typed<float>(column.values);
    case ScalarType::Float64:
      break;
  }
  return toArray(std::move(column.values));
}

namespace {
// Value i is written at byte sizeof(T) * i, below double i (byte 8 * i): once double i is read,
// nothing later reads the bytes its narrowed value overwrites. So a range of values [a, b) with
// b <= a * 8 / sizeof(T) writes only over doubles below a, read by the ranges before it, and
// reads none that it writes: its values can be narrowed in parallel. The ranges double in
// length (int32) or grow eightfold (uint8); 1M values are a few parallel passes, memory-bound
// like the copies in. memcpy keeps the two views of the bytes apart for the compiler (no
// type-punned pointers).
template <class T>
void narrowInPlace(unsigned char* bytes, std::size_t n) {
  static_assert(sizeof(T) < sizeof(double), "narrowing only");
  const auto narrow = [bytes](std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i) {
      double v;
      std::memcpy(&v, bytes + i * sizeof(double), sizeof(double));
      const T narrowed = T(v);
      std::memcpy(bytes + i * sizeof(T), &narrowed, sizeof(T));
    }
  };
  constexpr std::size_t kGrain = std::size_t(1) << 15;
  std::size_t a = std::min(n, kGrain);
  narrow(0, a);
  while (a < n) {
    const std::size_t b = std::min(n, a * (sizeof(double) / sizeof(T)));
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(a, b, kGrain),
        [&](const tbb::blocked_range<std::size_t>& r) { narrow(r.begin(), r.end()); });
    a = b;
  }
}

template <class T>
py::array narrowedInPlace(std::vector<double>&& values) {
  auto* owned = new std::vector<double>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  auto* bytes = reinterpret_cast<unsigned char*>(owned->data());
  narrowInPlace<T>(bytes, owned->size());
  return py::array_t<T>({py::ssize_t(owned->size())}, reinterpret_cast<const T*>(bytes), free);
}
}  // namespace

py::array resultColumnToArray(AttributeColumn&& column) {
  switch (column.type) {
    case ScalarType::Int8:
      return narrowedInPlace<std::int8_t>(std::move(column.values));
    case ScalarType::UInt8:
      return narrowedInPlace<std::uint8_t>(std::move(column.values));
    case ScalarType::Int16:
      return narrowedInPlace<std::int16_t>(std::move(column.values));
    case ScalarType::UInt16:
      return narrowedInPlace<std::uint16_t>(std::move(column.values));
    case ScalarType::Int32:
      return narrowedInPlace<std::int32_t>(std::move(column.values));
    case ScalarType::UInt32:
      return narrowedInPlace<std::uint32_t>(std::move(column.values));
    case ScalarType::Float32:
    case ScalarType::Float64:
      break;
  }
  return toArray(std::move(column.values));
}

ScalarType scalarTypeOf(const py::dtype& dtype, const std::string& name) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'b') return ScalarType::UInt8;
  if (kind == 'f' && size == 4) return ScalarType::Float32;
  if (kind == 'f' && size == 8) return ScalarType::Float64;
  if (kind == 'i' && size == 1) return ScalarType::Int8;
  if (kind == 'i' && size == 2) return ScalarType::Int16;
  if (kind == 'i' && size == 4) return ScalarType::Int32;
  if (kind == 'u' && size == 1) return ScalarType::UInt8;
  if (kind == 'u' && size == 2) return ScalarType::UInt16;
  if (kind == 'u' && size == 4) return ScalarType::UInt32;
  throwType("attribute '" + name +
            "': files hold int8..int32, uint8..uint32, float32, float64 or "
            "bool columns, got dtype " +
            dtypeName(dtype) + " (convert it, e.g. .astype(np.int32))");
}

std::vector<std::uint8_t> estimateAndOrient(PointCloud& cloud, std::size_t k,
                                            const std::string& orient,
                                            const std::optional<Vec3>& viewpoint,
                                            const ProgressCallback& progress, double acrossWeight,
                                            bool visibility, double sheetTolerance,
                                            std::size_t maxK, SheetSign sheetSign, bool reflect) {
  // The checks and defaults of the CLI's estimateAndOrient (cli/CloudCommands.cpp).
  if (k < 3) throw OptionError("k must be >= 3");
  if (sheetSign == SheetSign::FromPlanes && !(sheetTolerance > 0))
    throw OptionError("sign_from_pca needs sheet normals (sheet > 0)");
  if (sheetSign == SheetSign::ByRays && !(sheetTolerance > 0))
    throw OptionError("sign_by_rays needs sheet normals (sheet > 0)");
  OrientedNormalsOptions options;
  options.estimation.k = k;
  options.estimation.maxK = maxK;
  options.estimation.sheetTolerance = sheetTolerance;
  options.orientation.k = k;
  options.orientation.acrossWeight = acrossWeight;
  options.orientation.visibility = visibility;
  options.orientation.reflectAcrossBisector = reflect;
  options.sheetSign = sheetSign;
  return estimateAndOrient(cloud, options, orient, viewpoint, progress);
}

std::vector<std::uint8_t> estimateAndOrient(PointCloud& cloud, OrientedNormalsOptions options,
                                            const std::string& orient,
                                            const std::optional<Vec3>& viewpoint,
                                            const ProgressCallback& progress,
                                            NormalOrientationResult* orientation) {
  const std::size_t k = options.estimation.k;
  if (k >= cloud.size())
    throw OptionError("k " + std::to_string(k) + " must be smaller than the number of points (" +
                      std::to_string(cloud.size()) + ")");
  NormalOrientationOptions& o = options.orientation;
  if (orient == "mst") {
    o.method = OrientationMethod::MinimumSpanningTree;
    if (viewpoint) {  // each component faces it, as the CLI does with a PCD's VIEWPOINT
      o.faceViewpoint = true;
      o.viewpoint = *viewpoint - cloud.origin();
    }
  } else if (orient == "viewpoint") {
    if (!viewpoint) throw OptionError("orient='viewpoint' needs viewpoint=(x, y, z)");
    o.method = OrientationMethod::Viewpoint;
    o.viewpoint = *viewpoint - cloud.origin();  // the cloud works in recentred coordinates
  } else {
    throw OptionError("orient takes 'mst' or 'viewpoint', got '" + orient + "'");
  }
  const auto index = makeSpatialIndex(cloud.positions());
  OrientedNormals normals = estimateOrientedNormals(cloud.positions(), *index, options, progress);
  cloud.setNormals(std::move(normals.normals));
  std::vector<std::uint8_t> reliable = std::move(normals.orientation.reliable);
  if (orientation) *orientation = std::move(normals.orientation);
  return reliable;
}

std::optional<Vec3> asOptionalVec3(const py::handle& object, const char* name) {
  if (object.is_none()) return std::nullopt;
  const DoubleArray v = asDoubles(object, name, "three numbers");
  if (v.size() != 3) throwValue(std::string(name) + ": expected three numbers (x, y, z)");
  return Vec3(v.data()[0], v.data()[1], v.data()[2]);
}

void warn(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_RuntimeWarning, w.c_str(), 1) != 0) throw py::error_already_set();
}

void recordMainThread() { mainThread = std::this_thread::get_id(); }

Call::Call(py::object progress, std::optional<int> threads)
    : python_(std::move(progress)), threads_(threads.value_or(0)) {
  if (!python_.is_none() && !PyCallable_Check(python_.ptr()))
    throwType("progress: expected a callable (fraction, stage) -> bool | None");
  if (threads_ < 0) ThreadLimit check(threads_);  // the library's message for a bad count
  callback_ = [this](double fraction, std::string_view stage) { return report(fraction, stage); };
}

Call::~Call() = default;

bool Call::report(double fraction, std::string_view stage) {
  if (cancel_.load()) return false;
  if (python_.is_none()) return true;
  py::gil_scoped_acquire gil;
  if (cancel_.load()) return false;
  try {
    const py::object answer = python_(fraction, py::str(stage.data(), stage.size()));
    if (!answer.is_none() && !PyObject_IsTrue(answer.ptr())) cancel_ = true;
  } catch (py::error_already_set& e) {
    pending_ = std::make_unique<py::error_already_set>(std::move(e));
    cancel_ = true;
  }
  return !cancel_.load();
}

void Call::execute(const std::function<void()>& work) {
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        tbb::task_arena arena(threads_ > 0 ? threads_ : tbb::task_arena::automatic);
        arena.execute(work);
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
      finished.notify_one();
    });
    const bool canHandleSignals = std::this_thread::get_id() == mainThread;
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      if (!canHandleSignals || cancel_.load()) continue;
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
          pending_ = std::make_unique<py::error_already_set>();
          cancel_ = true;
        }
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  // The Python error that made the library stop (KeyboardInterrupt, the callback's exception)
  // is what the caller sees, not the Cancelled it became on the way.
  // An interrupt that came after the work's last check is raised all the same: the user asked.
  if (pending_) {
    const std::unique_ptr<py::error_already_set> pending = std::move(pending_);
    throw *pending;
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace scalespace::python
