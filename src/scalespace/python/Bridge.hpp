#pragma once
// What every binding file shares: NumPy arrays in and out, the library's errors as Python
// exceptions (option fields renamed to the keyword arguments), and running a library call with
// the GIL released, a Python progress callback and Ctrl-C.
//
// Arrays in: a C-contiguous float64 (N, 3) array is read in place; anything else array-like is
// converted once (np.asarray + one cast). Arrays out own their memory: a std::vector is moved
// into a capsule that NumPy frees with the array, so no array points into a C++ object that a
// later call frees.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/python/InputPool.hpp"

namespace scalespace::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// The library's message with its option fields (`CurvatureOptions::scaleK`) replaced by the
/// keyword arguments that set them (`scale_k`), as the CLI replaces them by its flags.
std::string withKeywords(std::string message);

/// Registers scalespace.Error and its subclasses OptionError (also a ValueError), FileError (also
/// an OSError) and Cancelled, and the translator from the library's exceptions to them.
void registerErrors(py::module_& m);

/// ValueError / TypeError with the library's wording, raised by the argument checks below.
[[noreturn]] void throwValue(const std::string& message);
[[noreturn]] void throwType(const std::string& message);

/// An (N, 3) float64 array held alive while `data` is read. `name` names the argument in errors.
struct Points {
  DoubleArray array;
  const Vec3* data = nullptr;
  std::size_t size = 0;
  /// The rows' bounds, found by asPoints in its check's pass (one pass less for makeCloud).
  std::optional<std::pair<Vec3, Vec3>> bounds;
};

/// Checks and converts an (N, 3) array of positions: a dtype that is not a number -> TypeError;
/// another shape, no rows, a NaN, infinite or absurd (beyond 1e100) coordinate -> ValueError
/// (the readers' wording: the row, what is wrong, how to fix it).
Points asPoints(const py::handle& object, const char* name = "points");

/// The same shape check for per-point vectors (normals: NaN allowed, as in files) of `rows` rows.
Points asVectors(const py::handle& object, std::size_t rows, const char* name);

/// A cloud from positions and optional normals (None: none), copied into the pool's buffers
/// (InputPool.hpp): memory the previous call already mapped in.
PooledCloud makeCloud(const Points& points, const py::handle& normals);

/// A 1-D integer array (point indices, labels) as `T`, with range checks against `limit` when
/// given (index >= limit -> ValueError naming `name`).
std::vector<std::uint32_t> asIndices(const py::handle& object, const char* name, std::size_t limit);

/// Moves `values` into a NumPy array of `shape` (the product must be values.size()).
template <class T>
py::array_t<T> toArray(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), free);
}

template <class T>
py::array_t<T> toArray(std::vector<T>&& values) {
  const py::ssize_t n = py::ssize_t(values.size());
  return toArray(std::move(values), {n});
}

/// (N, 3) float64 array of `vectors` (relative positions get `offset` added: absolute ones).
py::array_t<double> vectorsToArray(const std::vector<Vec3>& vectors,
                                   const Vec3& offset = Vec3::Zero());

/// A column as NumPy: float64 columns are moved as they are; with `nativeType`, every column
/// takes the dtype it has on file (uint8 colours stay uint8), which a write restores exactly.
py::array columnToArray(AttributeColumn&& column, bool nativeType);

/// A result column as NumPy without a copy, for results handed out once (curvature's columns):
/// float64 columns are moved as they are; an integer column (values held as double) is narrowed
/// to its type in its own buffer, which the array then owns. Allocating an exactly sized array
/// instead and freeing the double buffer cost about 2 ms per 8 MB (fresh pages in, the freed
/// ones unmapped); the price is the unused tail of the buffer (4 bytes per point for int32, 7
/// for uint8), held as long as the array.
py::array resultColumnToArray(AttributeColumn&& column);

/// The ScalarType a NumPy dtype is written as (TypeError for one files cannot hold).
ScalarType scalarTypeOf(const py::dtype& dtype, const std::string& name);

/// One library call with the GIL released. The call runs on a worker thread while the calling
/// thread, every 50 ms, takes the GIL to let Python handle signals (Ctrl-C raises
/// KeyboardInterrupt in the main thread only, and only while it runs Python's signal check);
/// a pending KeyboardInterrupt makes the library's progress callback return false, so the
/// library unwinds (Cancelled, no output left), and the interrupt is raised. `progress` is a
/// Python callable (fraction, stage) -> bool | None; False cancels (scalespace.Cancelled), an
/// exception it raises cancels and is raised. `threads` (None or 0 = all cores) bounds the
/// worker threads of this call only (a TBB arena).
class Call {
 public:
  Call(py::object progress, std::optional<int> threads);
  ~Call();
  Call(const Call&) = delete;
  Call& operator=(const Call&) = delete;

  /// What to pass to the library.
  const ProgressCallback& progress() const { return callback_; }
  int threads() const { return threads_; }

  template <class F>
  auto operator()(F&& f) -> decltype(f()) {
    using R = decltype(f());
    std::optional<R> result;
    execute([&] { result.emplace(f()); });
    return std::move(*result);
  }

 private:
  void execute(const std::function<void()>& work);
  bool report(double fraction, std::string_view stage);

  py::object python_;
  int threads_ = 0;
  ProgressCallback callback_;
  std::atomic<bool> cancel_{false};
  std::unique_ptr<py::error_already_set> pending_;  // raised by the callback or by Ctrl-C
};

/// Estimates (PCA over k neighbours, doubled up to maxK under heavy noise) and orients normals in
/// place, as `scalespace normals` and
/// the commands that need normals do: orient "mst" or "viewpoint" (then `viewpoint`, absolute
/// coordinates, is required). Returns the per-point reliability of the orientation. Needs no GIL.
std::vector<std::uint8_t> estimateAndOrient(
    PointCloud& cloud, std::size_t k = 10, const std::string& orient = "mst",
    const std::optional<Vec3>& viewpoint = std::nullopt, const ProgressCallback& progress = {},
    double acrossWeight = NormalOrientationOptions{}.acrossWeight,
    bool visibility = NormalOrientationOptions{}.visibility,
    double sheetTolerance = NormalEstimationOptions{}.sheetTolerance,
    std::size_t maxK = NormalEstimationOptions{}.maxK, SheetSign sheetSign = SheetSign::OwnTree,
    bool reflect = NormalOrientationOptions{}.reflectAcrossBisector);

/// Same with the estimation and orientation of `options` (e.g. cylinderNormalOptions()); `orient`
/// and `viewpoint` as above replace its orientation method and viewpoint. `orientation`, when
/// given, receives the orientation's result (closedSurface: the rays found every component
/// closed; openShare).
std::vector<std::uint8_t> estimateAndOrient(PointCloud& cloud, OrientedNormalsOptions options,
                                            const std::string& orient,
                                            const std::optional<Vec3>& viewpoint,
                                            const ProgressCallback& progress,
                                            NormalOrientationResult* orientation = nullptr);

/// Three numbers (x, y, z) or None.
std::optional<Vec3> asOptionalVec3(const py::handle& object, const char* name);

/// Issues the library's result warnings (mostly invalid fits) as Python RuntimeWarnings, as the
/// CLI prints them on stderr.
void warn(const std::vector<std::string>& warnings);

/// Records the main thread (the one importing the module): only it can handle signals.
void recordMainThread();

}  // namespace scalespace::python
