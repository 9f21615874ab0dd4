#pragma once
// Outputs of the plane pipeline: components.json / components.csv, outlines as OBJ polylines or
// PLY edges, the persistence diagram as SVG, and the saved PlaneModel (components.json +
// membership.bin) that `scalespace segment` reloads. Every file is written atomically.
// Plane offsets and outlines are written in absolute coordinates (positions + origin).
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/planes/PlaneQueries.hpp"

namespace scalespace {

/// One JSON object: {"scales": [...], "input": ..., "point_count": n, "components": [{"id",
/// "birth_level", "birth_scale", "death_level", "death_scale", "persistence",
/// "representative_level", "point_count", "normal": [x,y,z], "offset", "rms", "area"}]}.
void writeComponentsJson(const PlaneModel& model, const Vec3& origin, const std::string& input,
                         const std::string& path);
/// Header: id,birth_level,birth_scale,death_level,death_scale,persistence,nx,ny,nz,offset,rms,
/// area,point_count.
void writeComponentsCsv(const PlaneModel& model, const Vec3& origin, const std::string& path);

/// Adds the columns `segment` writes for per-point component labels (-1 none): plane_id (int32)
/// and red, green, blue (uint8, colorizeLabels: one colour per id, grey for -1). Replaces columns
/// of those names.
void addPlaneLabelColumns(PointCloud& cloud, const std::vector<int>& labels);

/// Outline loops as OBJ polylines ("l" elements, closed), one group "g component_<id>" each.
void writeOutlinesObj(const std::vector<PlaneComponent>& components, const Vec3& origin,
                      const std::string& path);
/// Outline loops as an ASCII PLY with vertices and edges (edge property "component").
void writeOutlinesPly(const std::vector<PlaneComponent>& components, const Vec3& origin,
                      const std::string& path);

/// Persistence diagram (Sec. 2.3.3): one dot per component at (birth scale, death scale), log
/// axes with decade labels, the diagonal y = x; dot colour = persistence (viridis).
void writePersistenceDiagramSvg(const PlaneModel& model, const std::string& path);

/// Saves membership.bin (magic "SSPM", uint64 points, uint32 levels, int32 ids level-major).
void writeMembership(const PointMembership& membership, const std::string& path);
PointMembership readMembership(const std::string& path);

/// Reads DIR/components.json and DIR/membership.bin (outlines are not reloaded). `input`
/// receives the path of the cloud the model was computed on. Throws FileError naming the file.
PlaneModel readPlaneModel(const std::string& directory, std::string* input = nullptr);

/// True if `directory` holds a result of writePlaneModel (membership.bin with its magic and
/// components.json).
bool isPlaneResult(const std::string& directory);
/// FileError unless `directory` is absent, an empty folder or an earlier planes result: the only
/// places writePlaneModel writes into (it never mixes its files with a user's).
void checkPlaneResultDestination(const std::string& directory);

/// Writes components.json, components.csv, outlines.obj, persistence.svg and membership.bin
/// into `directory` (created if needed; checkPlaneResultDestination first).
void writePlaneModel(const PlaneModel& model, const Vec3& origin, const std::string& input,
                     const std::string& directory);

}  // namespace scalespace
