// Bad requests lose nothing and say what is wrong (issue 16): outputs that would replace a user's
// files, segment queries at every level under the sanitizers, options that used to run without
// bound, invalid fits that used to pass silently, outputs checked before the work.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli/CliTestSupport.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/planes/PlaneExport.hpp"

namespace fs = std::filesystem;
using namespace scalespace;

namespace {

using test::Cli;
using test::Result;
using test::run;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

bool anyTemporaryLeft(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

// ------------------------------------------------------------------ 1. folders are never lost

TEST_F(Cli, ScalesNeverReplacesWhatIsNotAStack) {
  fs::create_directories(path("proj"));
  ASSERT_EQ(run("generate sphere -n 2000 -q -o " + path("proj/scan.ply")).code, 0);
  writeText(path("proj/notes.txt"), "x\n");
  // The folder that holds the input.
  Result r = run("scales " + path("proj/scan.ply") + " -o " + path("proj") + " --scales 3 -q");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("holds the input"), std::string::npos) << r.err;
  EXPECT_EQ(readText(path("proj/notes.txt")), "x\n");
  // A plain file and a user's folder.
  writeText(path("file.txt"), "keep\n");
  fs::create_directories(path("mine"));
  writeText(path("mine/a.txt"), "keep\n");
  writeText(path("mine/manifest.json"), "{\"format\": \"something else\"}\n");
  for (const std::string target : {"file.txt", "mine"}) {
    r = run("scales " + path("proj/scan.ply") + " -o " + path(target) + " --scales 3 -q");
    EXPECT_EQ(r.code, 1) << target << ": " << r.err;
    EXPECT_NE(r.err.find("is not a scale stack"), std::string::npos) << r.err;
  }
  EXPECT_EQ(readText(path("file.txt")), "keep\n");
  EXPECT_EQ(readText(path("mine/a.txt")), "keep\n");
  // A stack is replaced by a stack.
  ASSERT_EQ(
      run("scales " + path("proj/scan.ply") + " -o " + path("s.stack") + " --scales 2 -q").code, 0);
  r = run("scales " + path("proj/scan.ply") + " -o " + path("s.stack") + " --scales 3 -q");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(readText(path("s.stack/manifest.json")).find("\"scale_count\": 3"), std::string::npos);
  EXPECT_FALSE(anyTemporaryLeft(dir_));
}

TEST_F(Cli, PlanesWriteOnlyIntoANewOrEmptyFolderOrAnEarlierResult) {
  ASSERT_EQ(run("generate box -n 3000 -q -o " + path("box.ply")).code, 0);
  fs::create_directories(path("mine"));
  writeText(path("mine/components.json"), "my own\n");
  Result r = run("planes " + path("box.ply") + " -o " + path("mine") + " --scales 4 -q");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(readText(path("mine/components.json")), "my own\n");
  writeText(path("file.txt"), "keep\n");
  r = run("planes " + path("box.ply") + " -o " + path("file.txt") + " --scales 4 -q");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(readText(path("file.txt")), "keep\n");
  fs::create_directories(path("empty"));
  ASSERT_EQ(run("planes " + path("box.ply") + " -o " + path("empty") + " --scales 4 -q").code, 0);
  EXPECT_TRUE(isPlaneResult(path("empty")));
  r = run("planes " + path("box.ply") + " -o " + path("empty") + " --scales 5 -q");
  EXPECT_EQ(r.code, 0) << r.err;  // an earlier result is replaced
}

// -------------------------------------- 2. every segment query at every level (sanitizer build)

TEST_F(Cli, SegmentAnswersEveryQueryAtEveryLevel) {
  for (const std::string scene : {"stairs", "tri", "cubes"}) {
    SCOPED_TRACE(scene);
    const std::string in = path(scene + ".ply"), dir = path(scene + "_planes");
    ASSERT_EQ(run("generate " + scene + " -n 2000 --seed 4 -q -o " + in).code, 0);
    ASSERT_EQ(run("planes " + in + " -o " + dir + " --scales 5 -q").code, 0);
    const auto json = nlohmann::json::parse(readText(dir + "/components.json"));
    const auto scales = json.at("scales").get<std::vector<double>>();
    const int components = int(json.at("components").size());
    ASSERT_GT(components, 0);
    writeText(path("ids.txt"), "0 1 2 3 4 5 6 7 8 9 100 500 1999\n");
    std::vector<std::string> queries = {"--brush " + path("ids.txt"),
                                        "--similar 0 --within " + path("ids.txt"),
                                        "--min-persistence 0",
                                        "--min-persistence 3",
                                        "--scale 1e-9",
                                        "--scale 1e9"};
    for (double t : scales) queries.push_back("--scale " + std::to_string(t));
    for (const std::string& q : queries)
      for (const std::string extra : {"", " --extend-coverage"}) {
        const Result r = run("segment " + dir + " " + q + extra + " -q -o " + path("seg.ply"));
        EXPECT_EQ(r.code, 0) << q << extra << ": " << r.err;
        const PointCloud out = readCloud(path("seg.ply"));
        ASSERT_NE(out.findAttribute("plane_id"), nullptr);
        for (double id : out.findAttribute("plane_id")->values) {
          EXPECT_GE(id, -1);
          EXPECT_LT(id, components);
        }
      }
    // The recorded input is absolute: segment works from another folder.
    const Result r = run("segment " + dir + " --min-persistence 1 -q -o " + path("other/x.ply"));
    EXPECT_EQ(r.code, 0) << r.err;
  }
}

TEST_F(Cli, SegmentNamesInputWhenTheRecordedCloudIsGone) {
  ASSERT_EQ(run("generate box -n 2000 -q -o " + path("box.ply")).code, 0);
  // Planes run from the cloud's folder with a relative path; segment run from elsewhere.
  const std::string cli = SCALESPACE_CLI_PATH;
  ASSERT_EQ(
      std::system(
          ("cd " + dir_.string() + " && " + cli + " planes box.ply -o p --scales 4 -q").c_str()),
      0);
  ASSERT_EQ(std::system(("cd / && " + cli + " segment " + path("p") +
                         " --min-persistence 1 -q -o " + path("from_root.ply"))
                            .c_str()),
            0);
  fs::rename(path("box.ply"), path("moved.ply"));
  Result r = run("segment " + path("p") + " --min-persistence 1 -o " + path("x.ply"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--input"), std::string::npos) << r.err;
  r = run("segment " + path("p") + " --min-persistence 1 -q -o " + path("x.ply") + " --input " +
          path("moved.ply"));
  EXPECT_EQ(r.code, 0) << r.err;
}

// ------------------------------------------------------------- 3, 4. nothing runs without bound

TEST_F(Cli, OptionsThatWouldRunWithoutBoundAreRefusedOrClamped) {
  ASSERT_EQ(run("generate sphere -n 2000 -q -o " + path("s.ply")).code, 0);
  const auto start = std::chrono::steady_clock::now();
  Result r = run("normals " + path("s.ply") + " -o " + path("n.ply") + " --k 100000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--k"), std::string::npos) << r.err;
  r = run("normals " + path("s.ply") + " -o " + path("n.ply") + " --k 1500");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--k must be in [3, 1000]"), std::string::npos) << r.err;
  r = run("curvature " + path("s.ply") + " -o " + path("c.ply"));  // no scale at all
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("(--scale) or a neighbour count (--scale-k)"), std::string::npos) << r.err;
  r = run("curvature " + path("s.ply") + " -o " + path("c.ply") + " --scale-k 5000");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scale-k"), std::string::npos) << r.err;
  for (const std::string cmd : {"scales", "planes"}) {
    r = run(cmd + " " + path("s.ply") + " -o " + path("x") + " --scales 100000");
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_NE(r.err.find("--scales must be in [1, 1000]"), std::string::npos) << r.err;
  }
  r = run("render " + path("s.ply") + " -o " + path("r.png") + " --point-radius 1000000");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --point-radius"), std::string::npos) << r.err;
  // All of the above together, sanitizers included, in well under a minute.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60);
}

TEST_F(Cli, NormalsOfIdenticalPointsFinish) {
  std::ofstream xyz(path("same.xyz"));
  for (int i = 0; i < 20000; ++i) xyz << (i % 4 == 0 ? "1 2 3\n" : "1 2 4\n");
  xyz.close();
  const Result r = run("normals " + path("same.xyz") + " -o " + path("n.ply") + " -q");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readCloud(path("n.ply")).size(), 20000u);
}

// ---------------------------------------------------------------------- 5-7. nothing is silent

TEST_F(Cli, CurvatureToLasKeepsEveryComputedColumn) {
  ASSERT_EQ(run("generate sphere -n 3000 -q -o " + path("s.las")).code, 0);
  const Result r = run("curvature " + path("s.las") + " -o " + path("c.las") + " --scale 0.3 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud out = readCloud(path("c.las"));
  EXPECT_TRUE(out.hasNormals());
  for (const char* name : {"curv_mean", "curv_max", "dir_min_z", "gls_tau", "fit_valid"})
    EXPECT_NE(out.findAttribute(name), nullptr) << name;
}

TEST_F(Cli, MostlyInvalidFitsAreReportedWithTheirCause) {
  // Points on a line: every fit degenerate.
  std::ofstream line(path("line.xyz"));
  for (int i = 0; i < 500; ++i) line << i * 0.01 << ' ' << i * 0.02 << " 0 0 0 1\n";
  line.close();
  Result r = run("curvature " + path("line.xyz") + " -o " + path("l.ply") + " --scale 0.2 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: 500 of 500 fits"), std::string::npos) << r.err;
  EXPECT_EQ(readCloud(path("l.ply")).findAttribute("fit_valid")->values,
            std::vector<double>(500, 0));
  // NaN normals and a scale larger than the cloud: said on stderr and in the JSON.
  ASSERT_EQ(run("generate sphere -n 3000 -q -o " + path("s.xyz")).code, 0);
  PointCloud s = readCloud(path("s.xyz"));
  for (std::size_t i = 0; i < s.size(); i += 3) s.normals()[i] = Vec3::Constant(std::nan(""));
  writeCloud(s, path("nan.ply"));
  r = run("info " + path("nan.ply"));
  EXPECT_NE(r.out.find("1000 of 3000 NaN/Inf or zero"), std::string::npos) << r.out;
  r = run("curvature " + path("nan.ply") + " -o " + path("n.ply") + " --scale 0.3 -q");
  EXPECT_NE(r.err.find("1000 input normals are NaN/Inf"), std::string::npos) << r.err;
  EXPECT_NE(readText(path("n.json")).find("1000 input normals are NaN/Inf"), std::string::npos);
  for (const std::string cmd : {"scales", "planes"}) {
    r = run(cmd + " " + path("nan.ply") + " -o " + path(cmd + "_out") + " --scales 3 -q");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("1000 input normals are NaN/Inf"), std::string::npos) << cmd << r.err;
  }
  r = run("curvature " + path("s.xyz") + " -o " + path("big.ply") + " --scale 1e7 -q");
  EXPECT_NE(r.err.find("times the cloud's diagonal"), std::string::npos) << r.err;
  // A healthy run has no warning.
  r = run("curvature " + path("s.xyz") + " -o " + path("ok.ply") + " --scale 0.3 -q");
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(readText(path("ok.json")).find("\"warnings\": []"), std::string::npos);
}

// ------------------------------------------------------- 8. outputs checked before any work

TEST_F(Cli, OutputsAreCheckedBeforeTheInputIsRead) {
  // The input is malformed: an error about it would mean the work started before the check.
  writeText(path("bad.ply"), "ply\nformat ascii 1.0\nelement vertex 9\nend_header\n1 2\n");
  writeText(path("file.txt"), "keep\n");
  fs::create_directories(path("folder"));
  const std::vector<std::string> calls = {
      "planes " + path("bad.ply") + " -o " + path("file.txt"),
      "curvature " + path("bad.ply") + " -o " + path("out.jpg") + " --scale 1",
      "curvature " + path("bad.ply") + " -o " + path("out.obj") + " --scale 1",
      "curvature " + path("bad.ply") + " -o " + path("folder") + " --scale 1",
      "curvature " + path("bad.ply") + " -o " + path("file.txt/x.ply") + " --scale 1",
      "normals " + path("bad.ply") + " -o " + path("bad.ply"),
      "render " + path("bad.ply") + " -o " + path("x.jpg"),
      "scales " + path("bad.ply") + " -o " + path("file.txt")};
  for (const std::string& call : calls) {
    const Result r = run(call);
    EXPECT_NE(r.code, 0) << call;
    EXPECT_EQ(r.err.find("bad.ply: line"), std::string::npos) << call << ": " << r.err;
  }
  EXPECT_EQ(readText(path("file.txt")), "keep\n");
  // Missing folders are created, for files as for folders.
  ASSERT_EQ(run("generate sphere -n 500 -q -o " + path("a/b/s.ply")).code, 0);
  EXPECT_EQ(
      run("curvature " + path("a/b/s.ply") + " -o " + path("c/d/k.ply") + " --scale 0.5 -q").code,
      0);
  EXPECT_TRUE(fs::exists(path("c/d/k.ply")) && fs::exists(path("c/d/k.json")));
}

TEST_F(Cli, OutputsNeverReplaceAFileOfAnInputFolder) {
  ASSERT_EQ(run("generate box -n 2000 -q -o " + path("box.ply")).code, 0);
  ASSERT_EQ(run("planes " + path("box.ply") + " -o " + path("p") + " --scales 4 -q").code, 0);
  const std::string table = readText(path("p/components.csv"));
  // components.csv is a cloud extension: segment wrote its labelled points over the table.
  const Result r =
      run("segment " + path("p") + " --min-persistence 1 -q -o " + path("p/components.csv"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("is a file of the input"), std::string::npos) << r.err;
  EXPECT_EQ(readText(path("p/components.csv")), table);
  // The user's own files inside the folder may be written and replaced.
  for (int pass = 0; pass < 2; ++pass)
    EXPECT_EQ(
        run("segment " + path("p") + " --min-persistence 1 -q -o " + path("p/labels.ply")).code, 0);
}

// --------------------------------------------------------------------------- 9. smaller ones

TEST_F(Cli, MeshesCanBeSampledByArea) {
  writeText(path("quad.off"), "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  Result r = run("normals " + path("quad.off") + " --sample 500 -q -o " + path("q.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readCloud(path("q.ply")).size(), 500u);
  ASSERT_EQ(run("generate sphere -n 100 -q -o " + path("s.xyz")).code, 0);
  r = run("normals " + path("s.xyz") + " --sample 500 -o " + path("x.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--sample applies to meshes"), std::string::npos) << r.err;
  // A PLY is a mesh when it has faces; one without is refused with the reason.
  writeText(path("quad.ply"),
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  r = run("normals " + path("quad.ply") + " --sample 500 -q -o " + path("qp.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readCloud(path("qp.ply")).size(), 500u);
  ASSERT_EQ(run("generate sphere -n 100 -q -o " + path("s.ply")).code, 0);
  r = run("normals " + path("s.ply") + " --sample 500 -q -o " + path("x.ply"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("no faces to sample"), std::string::npos) << r.err;
}

TEST_F(Cli, WrongExtensionsAndValuesAreRefused) {
  ASSERT_EQ(run("generate sphere -n 500 -q -o " + path("s.ply")).code, 0);
  ASSERT_EQ(run("scales " + path("s.ply") + " -o " + path("s.stack") + " --scales 2 -q").code, 0);
  Result r = run("export " + path("s.stack") + " --point 3 -o " + path("p.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(path("p.ply")));
  EXPECT_EQ(run("export " + path("s.stack") + " --point 3 -o " + path("p.csv")).code, 0);
  ASSERT_EQ(run("generate box -n 2000 -q -o " + path("box.ply")).code, 0);
  ASSERT_EQ(run("planes " + path("box.ply") + " -o " + path("p") + " --scales 4 -q").code, 0);
  for (const std::string bad :
       {"--coverage-distance -1", "--coverage-angle 100", "--area-tolerance -1"}) {
    r = run("segment " + path("p") + " --min-persistence 1 --extend-coverage " + bad + " -o " +
            path("x.ply"));
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find(bad.substr(0, bad.find(' '))), std::string::npos) << r.err;
  }
}

TEST_F(Cli, NonFiniteCoordinatesNameTheFlagAndInfoCountsThem) {
  writeText(path("nan.xyz"), "0 0 0\n1 nan 0\n0 1 0\n1 1 0\n");
  Result r = run("normals " + path("nan.xyz") + " -o " + path("n.ply"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--drop-invalid"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("ReadOptions"), std::string::npos) << r.err;
  r = run("info " + path("nan.xyz"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("points      3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 more points with NaN/Inf"), std::string::npos) << r.out;
}

TEST_F(Cli, SixteenBitColoursBecomeEightBitInPly) {
  PointCloud c;
  c.setAbsolutePositions({Vec3(0, 0, 0), Vec3(1, 0, 0)});
  for (const char* name : {"red", "green", "blue"})
    c.addAttribute(name, ScalarType::UInt16).values = {65535, 257 * 16};
  writeCloud(c, path("c.las"));
  const PointCloud las = readCloud(path("c.las"));
  writeCloud(las, path("c.ply"));
  const PointCloud ply = readCloud(path("c.ply"));
  EXPECT_EQ(ply.findAttribute("red")->type, ScalarType::UInt8);
  EXPECT_EQ(ply.findAttribute("blue")->values, (std::vector<double>{255, 16}));
}

TEST_F(Cli, AnInterruptedStackLeavesNothingBehind) {
  ASSERT_EQ(run("generate stairs -n 60000 -q -o " + path("st.ply")).code, 0);
  const std::string cmd = std::string(SCALESPACE_CLI_PATH) + " scales " + path("st.ply") + " -o " +
                          path("st.stack") + " --scales 40 --threads 1 -q";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Interrupt once the temporary stack exists (the run is well into its work).
  bool started = false;
  for (int i = 0; i < 400 && !started; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    for (const auto& e : fs::directory_iterator(dir_))
      started = started || e.path().filename().string().find("st.stack.tmp-") == 0;
  }
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(started);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(anyTemporaryLeft(dir_));
  EXPECT_FALSE(fs::exists(path("st.stack")));
}

}  // namespace
