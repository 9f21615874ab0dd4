// The meshless parametrization of Chapter 4 (scalespace parametrize) against the peers a user
// has today, on the shapes of param/ParamShapes (disk, sphere, annulus and torus topology),
// clean and noisy (1e-3 of the diagonal):
//   - naive point baselines: the PCA-plane projection (disk shapes) and the radial projection
//     from the centroid (the others);
//   - a mesh parametrizer on the generating mesh (disk shapes): CGAL Surface_mesh_
//     parameterization's LSCM (free border) and discrete authalic (circular border).
// Every map is scored by the same meshless measures (param/MeshlessDistortion, MapDefects):
// the share of points that fold or overlap, and the median eps_conf and eps_auth (Eq. 4.3-4.4)
// at 16 and 64 neighbours, and the median stretch of the 16-neighbour local maps (the ratio of
// their singular values, MapDefects::stretch). The mesh peers are scored on the mesh's vertices.
//
// Rows: "scalespace" is `parametrize`'s default (the flattening, then the robust relaxation of
// the domain: rigid on a plane, mostly conformal on a sphere), "thesis" the flattening alone
// (--relax 0), "+conformal", "+rigid" and "+1round" the other relaxations (similarities,
// rotations on both domains; one plain least-squares round).
//
//   bench_parametrize [--points N (100000)] [--shapes a,b,...] [--noise list (0,0.001)]
//                     [--scales M (50)] [--resolution R (128): the peers' mesh grid]
//                     [--no-peers] [--threads T] [--relax-iterations I (5)]
//                     [--relax-max-solve N (100000)] [--relax-large-spheres]
//                     [--rigidity R] [--sphere-rigidity R] (the "scalespace" and "+1round" rows;
//                     default: the library's): the relaxations' options
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/Discrete_authalic_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/param/ConformalRelaxation.hpp"
#include "scalespace/param/MeshlessDistortion.hpp"
#include "scalespace/param/ParamShapes.hpp"
#include "scalespace/param/Parametrization.hpp"

using namespace scalespace;

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = Mesh::Vertex_index;
namespace SMP = CGAL::Surface_mesh_parameterization;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Score {
  std::string method;
  double folds = 0, overlaps = 0;  // % of the points
  double conf16 = 0, auth16 = 0, conf64 = 0, auth64 = 0;
  double stretch = 0;  // median singular-value ratio of the 16-neighbour local maps
  double seconds = 0;
  std::string note;
};

Score scoreMap(const std::string& method, const std::vector<Vec3>& positions,
               const std::vector<Vec3>& normals, const DomainMap& domain, double seconds) {
  Score s;
  s.method = method;
  s.seconds = seconds;
  const MapDefects defects = findMapDefects(positions, normals, domain);
  const double n = double(positions.size());
  s.folds = 100.0 * double(defects.folds) / n;
  s.overlaps = 100.0 * double(defects.overlaps) / n;
  s.stretch = defects.medianStretch;
  const DistortionResult d = measureDistortion(positions, normals, domain, {{16, 64}});
  s.conf16 = d.sizes[0].medianConformal;
  s.auth16 = d.sizes[0].medianAuthalic;
  s.conf64 = d.sizes[1].medianConformal;
  s.auth64 = d.sizes[1].medianAuthalic;
  return s;
}

/// PCA-plane projection: (u, v) on the two main axes, (u, v, mean normal) right-handed.
DomainMap pcaPlane(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals) {
  Vec3 mean = Vec3::Zero(), meanNormal = Vec3::Zero();
  for (const Vec3& p : positions) mean += p;
  mean /= double(positions.size());
  Mat3 cov = Mat3::Zero();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3 d = positions[i] - mean;
    cov += d * d.transpose();
    meanNormal += normals[i];
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 a = eig.eigenvectors().col(2);
  Vec3 b = eig.eigenvectors().col(1);
  if (a.cross(b).dot(meanNormal) < 0) b = -b;
  std::vector<Vec2> uv;
  for (const Vec3& p : positions) uv.emplace_back((p - mean).dot(a), (p - mean).dot(b));
  return domainFromCoordinates(uv, {});
}

/// Radial projection from the centroid onto the unit sphere.
DomainMap radial(const std::vector<Vec3>& positions) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : positions) mean += p;
  mean /= double(positions.size());
  std::vector<Vec3> directions;
  for (const Vec3& p : positions)
    directions.push_back((p - mean).norm() > 0 ? Vec3((p - mean).normalized()) : Vec3::UnitZ());
  return domainFromCoordinates({}, directions);
}

/// A CGAL parametrization of the mesh, scored on its vertices.
template <class Parameterizer>
Score meshPeer(const std::string& method, const TriangleMesh& source) {
  Mesh mesh;
  std::vector<VertexIndex> vertex;
  for (const Vec3& p : source.vertices) vertex.push_back(mesh.add_vertex({p.x(), p.y(), p.z()}));
  for (const auto& t : source.triangles) mesh.add_face(vertex[t[0]], vertex[t[1]], vertex[t[2]]);
  // Vertices of no triangle (outside the clipped grid) are not part of the surface.
  std::vector<Vec3> positions, normals;
  std::vector<VertexIndex> used;
  for (std::size_t i = 0; i < source.vertices.size(); ++i)
    if (!mesh.is_isolated(vertex[i])) {
      used.push_back(vertex[i]);
      positions.push_back(source.vertices[i]);
      normals.push_back(source.normals[i]);
    }
  const auto border = CGAL::Polygon_mesh_processing::longest_border(mesh).first;
  auto uvMap = mesh.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  const auto start = std::chrono::steady_clock::now();
  const SMP::Error_code status = SMP::parameterize(mesh, Parameterizer(), border, uvMap);
  const double seconds = secondsSince(start);
  if (status != SMP::OK) {
    Score s;
    s.method = method;
    s.seconds = seconds;
    s.note = SMP::get_error_message(status);
    return s;
  }
  std::vector<Vec2> uv;
  for (VertexIndex v : used) uv.emplace_back(uvMap[v].x(), uvMap[v].y());
  Score s = scoreMap(method, positions, normals, domainFromCoordinates(uv, {}), seconds);
  s.note = std::to_string(positions.size()) + " vertices";
  return s;
}

void print(const std::string& shape, double noise, const Score& s) {
  if (!s.note.empty() && s.conf16 == 0) {
    std::printf("%-15s %-7g %-16s %s (%.2f s)\n", shape.c_str(), noise, s.method.c_str(),
                s.note.c_str(), s.seconds);
    return;
  }
  std::printf("%-15s %-7g %-16s %7.3f %8.3f %7.3f %7.3f %7.3f %7.3f %7.3f %8.2f  %s\n",
              shape.c_str(), noise, s.method.c_str(), s.folds, s.overlaps, s.conf16, s.auth16,
              s.conf64, s.auth64, s.stretch, s.seconds, s.note.c_str());
  std::fflush(stdout);
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

}  // namespace

static int run(int argc, char** argv) {
  std::size_t points = 100000;
  std::vector<ParamShape> shapes = allParamShapes();
  std::vector<double> noises{0, 1e-3};
  int scales = 50, resolution = 128, threads = 0, relaxIterations = 5;
  std::size_t relaxMaxSolve = RelaxationOptions{}.maxSolvePoints;
  bool peers = true, largeSpheres = false;
  double rigidity = RelaxationOptions{}.rigidity,
         sphereRigidity = RelaxationOptions{}.sphereRigidity;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--points" && i + 1 < argc) {
      points = scalespace::bench::countArgument(argv, ++i);
    } else if (a == "--shapes" && i + 1 < argc) {
      shapes.clear();
      for (const std::string& s : split(argv[++i])) shapes.push_back(parseParamShape(s));
    } else if (a == "--noise" && i + 1 < argc) {
      noises.clear();
      for (const std::string& s : split(argv[++i]))
        noises.push_back(scalespace::bench::parseNumber("--noise", s));
    } else if (a == "--scales" && i + 1 < argc) {
      scales = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--resolution" && i + 1 < argc) {
      resolution = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--threads" && i + 1 < argc) {
      threads = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--relax-iterations" && i + 1 < argc) {
      relaxIterations = scalespace::bench::integerArgument(argv, ++i);
    } else if (a == "--relax-max-solve" && i + 1 < argc) {
      relaxMaxSolve = scalespace::bench::countArgument(argv, ++i);
    } else if (a == "--no-peers") {
      peers = false;
    } else if (a == "--relax-large-spheres") {
      largeSpheres = true;
    } else if (a == "--rigidity" && i + 1 < argc) {
      rigidity = scalespace::bench::numberArgument(argv, ++i);
    } else if (a == "--sphere-rigidity" && i + 1 < argc) {
      sphereRigidity = scalespace::bench::numberArgument(argv, ++i);
    } else {
      std::fprintf(stderr,
                   "usage: bench_parametrize [--points N] [--shapes a,b] [--noise 0,0.001] "
                   "[--scales M] [--resolution R] [--no-peers] [--threads T] "
                   "[--relax-iterations I] [--relax-max-solve N] [--relax-large-spheres] "
                   "[--rigidity R] [--sphere-rigidity R]\n");
      return 2;
    }
  }
  ThreadLimit limit(threads);
  std::printf("points %zu, scales %d, peers' mesh grid %d, threads %zu\n", points, scales,
              resolution, ThreadLimit::active());
  std::printf("%-15s %-7s %-16s %7s %8s %7s %7s %7s %7s %7s %8s\n", "shape", "noise", "method",
              "folds%", "overlap%", "conf16", "auth16", "conf64", "auth64", "stretch", "seconds");
  for (ParamShape shape : shapes) {
    const std::string name = paramShapeName(shape);
    const ParamTopology topology = paramShapeTopology(shape);
    for (double noise : noises) {
      ParamShapeOptions generate;
      generate.pointCount = points;
      generate.noise = noise;
      const PointCloud cloud = generateParamShape(shape, generate);
      std::vector<Vec3> positions(cloud.size());
      for (std::size_t i = 0; i < cloud.size(); ++i) positions[i] = cloud.absolutePosition(i);
      const std::vector<Vec3>& normals = cloud.normals();

      // The thesis' map (no relaxation), then the relaxations: the default (robust), the
      // conformal one (similarities), the rigid one (rotations) and the plain least-squares one.
      ParametrizationOptions options;
      options.flattening.scaleCount = scales;
      options.relaxation.iterations = 0;
      const auto start = std::chrono::steady_clock::now();
      const Parametrization thesis = parametrize(positions, normals, options);
      const double seconds = secondsSince(start);
      const std::string domainNote = std::string(domainKindName(thesis.domain.kind)) +
                                     (thesis.oneToOne ? "" : ", flagged not one-to-one");
      const bool relaxable = relaxIterations > 0;
      struct Variant {
        const char* method;
        double rigidity, sphereRigidity;
        int rounds;
      };
      const int rounds = RelaxationOptions{}.rounds;
      const Variant variants[] = {{"scalespace", rigidity, sphereRigidity, rounds},
                                  {"+conformal", 0, 0, rounds},
                                  {"+rigid", 1, 1, rounds},
                                  {"+1round", rigidity, sphereRigidity, 1}};
      for (const Variant& v : variants) {
        if (!relaxable && v.method != variants[0].method) continue;
        DomainMap map = thesis.domain;
        RelaxationOptions relax;
        relax.iterations = relaxIterations;
        relax.maxSolvePoints = relaxMaxSolve;
        relax.largeSpheres = largeSpheres;
        relax.rigidity = v.rigidity;
        relax.sphereRigidity = v.sphereRigidity;
        relax.rounds = v.rounds;
        const RelaxationResult r =
            relaxable ? relaxConformally(positions, normals, map, relax) : RelaxationResult{};
        Score score = scoreMap(v.method, positions, normals, map, seconds + r.seconds);
        score.note = domainNote;
        if (relaxable)
          score.note += r.applied ? ", relaxed in " + std::to_string(r.seconds) + " s"
                                  : ", not relaxed: " + r.reason;
        print(name, noise, score);
      }
      Score plain = scoreMap("thesis", positions, normals, thesis.domain, seconds);
      plain.note = domainNote;
      print(name, noise, plain);

      const bool disk = topology == ParamTopology::Disk;
      const auto t0 = std::chrono::steady_clock::now();
      const DomainMap naive = disk ? pcaPlane(positions, normals) : radial(positions);
      print(name, noise,
            scoreMap(disk ? "pca-plane" : "radial", positions, normals, naive, secondsSince(t0)));
      if (peers && disk && noise == noises.front()) {
        const TriangleMesh mesh = paramShapeMesh(shape, resolution);
        print(name, noise, meshPeer<SMP::LSCM_parameterizer_3<Mesh>>("cgal-lscm", mesh));
        print(name, noise,
              meshPeer<SMP::Discrete_authalic_parameterizer_3<Mesh>>("cgal-authalic", mesh));
      }
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_parametrize", [&] { return run(argc, argv); });
}
