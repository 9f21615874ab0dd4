// `scalespace view` as a program: what it opens and refuses, the URL it prints, the data it then
// serves (the labels `segment` writes), a port in use, and a clean stop on SIGTERM.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli/CliTestSupport.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"

namespace scalespace::test {
namespace {

// A running `scalespace view ARGS`: its URL (first stdout line), stopped with SIGTERM.
class ViewProcess {
 public:
  explicit ViewProcess(const std::vector<std::string>& args) {
    int out[2];
    if (::pipe(out) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      ::close(out[0]);
      std::vector<char*> argv{const_cast<char*>(SCALESPACE_CLI_PATH), const_cast<char*>("view")};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(SCALESPACE_CLI_PATH, argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_ = out[0];
    std::string line;
    char c;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline && ::read(stdout_, &c, 1) == 1 && c != '\n')
      line += c;
    // "scalespace view: http://127.0.0.1:PORT/?token=TOKEN" (no std::regex: GCC 12 warns on it
    // under the sanitizers, and warnings are errors).
    const std::string prefix = "http://127.0.0.1:", key = "/?token=";
    const std::size_t at = line.find(prefix), mark = line.find(key);
    if (at != std::string::npos && mark != std::string::npos && mark > at + prefix.size()) {
      port = std::atoi(line.c_str() + at + prefix.size());
      token = line.substr(mark + key.size());
      if (token.size() != 32 || token.find_first_not_of("0123456789abcdef") != std::string::npos)
        port = 0;
    }
  }
  ~ViewProcess() { stop(); }
  // SIGTERM, then the exit code (-1 when killed otherwise).
  int stop() {
    if (pid_ <= 0) return exitCode_;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ::close(stdout_);
    pid_ = 0;
    exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return exitCode_;
  }
  // Status line and body of GET `target` (Connection: close).
  std::pair<int, std::string> get(const std::string& target) const {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd);
      return {-1, ""};
    }
    const std::string request = "GET " + target +
                                " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                                "\r\nConnection: close\r\n\r\n";
    (void)!::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    std::string answer;
    char buffer[65536];
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;)
      answer.append(buffer, std::size_t(n));
    ::close(fd);
    const std::size_t body = answer.find("\r\n\r\n");
    if (answer.compare(0, 9, "HTTP/1.1 ") != 0 || body == std::string::npos) return {-1, answer};
    return {std::atoi(answer.c_str() + 9), answer.substr(body + 4)};
  }
  int port = 0;
  std::string token;

 private:
  pid_t pid_ = 0;
  int stdout_ = -1;
  int exitCode_ = -1;
};

class CliView : public Cli {
 protected:
  // A small planes result of the generated house.
  void makePlanes() {
    ASSERT_EQ(run("generate house -n 6000 --noise 0.001 -o " + path("house.ply") + " -q").code, 0);
    const Result r =
        run("planes " + path("house.ply") + " -o " + path("planes") + " --scales 8 -q");
    ASSERT_EQ(r.code, 0) << r.err;
  }
};

TEST_F(CliView, ServesAPlanesResultWithSegmentsLabelsAndStopsOnSigterm) {
  makePlanes();
  ViewProcess view({path("planes"), "--no-browser", "-q", "--export-dir", dir_.string()});
  ASSERT_GT(view.port, 0) << "no URL printed";
  const auto manifest = view.get("/api/manifest?token=" + view.token);
  ASSERT_EQ(manifest.first, 200);
  EXPECT_NE(manifest.second.find("\"planes\""), std::string::npos);
  EXPECT_EQ(view.get("/api/manifest").first, 403);
  EXPECT_EQ(view.get("/api/manifest?token=" + std::string(32, '0')).first, 403);

  ASSERT_EQ(
      run("segment " + path("planes") + " --min-persistence 2 -o " + path("seg.ply") + " -q").code,
      0);
  const auto labels = view.get("/api/planes/labels?min_persistence=2&token=" + view.token);
  ASSERT_EQ(labels.first, 200);
  const PointCloud segmented = readCloud(path("seg.ply"));
  const AttributeColumn* id = segmented.findAttribute("plane_id");
  ASSERT_NE(id, nullptr);
  ASSERT_EQ(labels.second.size(), 4 * segmented.size());
  // The served arrays follow the drawn points (/api/cloud/indices): every point, coarse to fine.
  const auto drawn = view.get("/api/cloud/indices?token=" + view.token);
  ASSERT_EQ(drawn.second.size(), labels.second.size());
  for (std::size_t k = 0; k < segmented.size(); ++k) {
    std::int32_t v;
    std::uint32_t i;
    std::memcpy(&v, labels.second.data() + 4 * k, 4);
    std::memcpy(&i, drawn.second.data() + 4 * k, 4);
    ASSERT_LT(i, segmented.size());
    ASSERT_EQ(v, id->values[i]) << "point " << i;
  }
  EXPECT_EQ(view.stop(), 0);
}

TEST_F(CliView, ServesAPlainCloud) {
  ASSERT_EQ(run("generate sphere -n 2000 -o " + path("s.ply") + " -q").code, 0);
  ViewProcess view({path("s.ply"), "--no-browser", "-q"});
  ASSERT_GT(view.port, 0);
  const auto positions = view.get("/api/cloud/positions?token=" + view.token);
  EXPECT_EQ(positions.first, 200);
  EXPECT_EQ(positions.second.size(), 2000u * 12);
  EXPECT_EQ(view.get("/api/planes/labels?level=0&token=" + view.token).first, 404);
  EXPECT_EQ(view.stop(), 0);
}

TEST_F(CliView, ServesAStackWithTheValuesOfExport) {
  ASSERT_EQ(run("generate sphere -n 2000 -o " + path("s.ply") + " -q").code, 0);
  ASSERT_EQ(run("scales " + path("s.ply") + " -o " + path("s.stack") + " --scales 4 -q").code, 0);
  ViewProcess view({path("s.stack"), "--no-browser", "-q"});
  ASSERT_GT(view.port, 0) << "no URL printed";
  const auto manifest = view.get("/api/manifest?token=" + view.token);
  ASSERT_EQ(manifest.first, 200);
  EXPECT_NE(manifest.second.find("\"kind\":\"stack\""), std::string::npos) << manifest.second;
  EXPECT_EQ(view.get("/api/cloud/positions?token=" + view.token).second.size(), 2000u * 12);
  const auto values = view.get("/api/stack/values?quantity=curv_mean&scale=1&token=" + view.token);
  ASSERT_EQ(values.first, 200);
  ASSERT_EQ(values.second.size(), 2000u * 4);
  ASSERT_EQ(run("export " + path("s.stack") + " --scale 1 -o " + path("s1.ply") + " -q").code, 0);
  const PointCloud exported = readCloud(path("s1.ply"));
  const AttributeColumn* h = exported.findAttribute("curv_mean");
  ASSERT_NE(h, nullptr);
  for (std::size_t i = 0; i < 2000; ++i) {
    float v;
    std::memcpy(&v, values.second.data() + 4 * i, 4);
    ASSERT_EQ(v, float(h->values[i])) << "point " << i;
  }
  EXPECT_EQ(view.get("/api/stack/values?quantity=curv_mean&scale=4&token=" + view.token).first,
            400);
  EXPECT_EQ(view.get("/api/stack/series?point=2000&token=" + view.token).first, 400);
  EXPECT_EQ(view.stop(), 0);
}

TEST_F(CliView, DrawsLinesOverACloudAndAlone) {
  ASSERT_EQ(run("generate torus -n 3000 -o " + path("t.ply") + " -q").code, 0);
  const Result lines = run("lines " + path("t.ply") + " -o " + path("l.ply") + " --scales 1 -q");
  ASSERT_EQ(lines.code, 0) << lines.err;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{path("t.ply"), "--lines", path("l.ply")},
        std::vector<std::string>{path("l.ply")}}) {
    std::vector<std::string> all = args;
    all.insert(all.end(), {"--no-browser", "-q"});
    ViewProcess view(all);
    ASSERT_GT(view.port, 0) << "no URL printed";
    const auto manifest =
        nlohmann::json::parse(view.get("/api/manifest?token=" + view.token).second);
    const std::size_t segments = manifest.at("lines").at("segment_count");
    EXPECT_GT(segments, 0u);
    EXPECT_EQ(view.get("/api/lines/segments?token=" + view.token).second.size(), 8 * segments);
    EXPECT_EQ(view.stop(), 0);
  }
  const Result notLines =
      run("view " + path("t.ply") + " --lines " + path("t.ply") + " --no-browser");
  EXPECT_NE(notLines.code, 0);
  EXPECT_NE(notLines.err.find("edge element"), std::string::npos) << notLines.err;
}

TEST_F(CliView, ServesACylindersResultWithItsAxes) {
  ASSERT_EQ(run("generate pipes -n 20000 -o " + path("p.ply") + " -q").code, 0);
  ASSERT_EQ(run("cylinders " + path("p.ply") + " -o " + path("cyl") + " -q").code, 0);
  const PolylineSet axes = readPolylines(path("cyl/axes.ply"));
  ASSERT_GT(axes.lineCount(), 0u);
  ViewProcess view({path("cyl"), "--no-browser", "-q"});
  ASSERT_GT(view.port, 0) << "no URL printed";
  const auto manifest = nlohmann::json::parse(view.get("/api/manifest?token=" + view.token).second);
  EXPECT_EQ(manifest.at("source").at("kind"), "cylinders") << manifest.dump();
  EXPECT_EQ(view.get("/api/cloud/positions?token=" + view.token).second.size(), 20000u * 12);
  const auto attributes = manifest.at("cloud").dump();
  EXPECT_NE(attributes.find("cylinder_id"), std::string::npos) << attributes;
  std::size_t edges = 0;
  for (std::size_t l = 0; l < axes.lineCount(); ++l)
    edges += axes.lineSize(l) - 1 + (axes.isClosed(l) ? 1 : 0);
  EXPECT_EQ(manifest.at("lines").at("segment_count"), edges);
  EXPECT_EQ(view.stop(), 0);
}

TEST_F(CliView, DecimatesBeyondThePointBudget) {
  ASSERT_EQ(run("generate sphere -n 1000 -o " + path("s.ply") + " -q").code, 0);
  ViewProcess view({path("s.ply"), "--no-browser", "-q", "--point-budget", "300"});
  ASSERT_GT(view.port, 0);
  EXPECT_EQ(view.get("/api/cloud/positions?token=" + view.token).second.size(), 300u * 12);
  EXPECT_EQ(view.get("/api/cloud/indices?token=" + view.token).second.size(), 300u * 4);
}

TEST_F(CliView, RefusesWhatItCannotOpen) {
  fs::create_directories(path("folder"));
  Result r = run("view " + path("folder") + " --no-browser");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("not a `scalespace planes` or `cylinders` result"), std::string::npos)
      << r.err;
  r = run("view " + path("missing.ply") + " --no-browser");
  EXPECT_NE(r.code, 0);
  r = run("view " + path("folder") + " --port 70000 --no-browser");
  EXPECT_EQ(r.code, 2);
  r = run("view " + path("folder") + " --point-budget 0 --no-browser");
  EXPECT_EQ(r.code, 2);
}

TEST_F(CliView, RefusesAPortInUse) {
  ASSERT_EQ(run("generate sphere -n 500 -o " + path("s.ply") + " -q").code, 0);
  ViewProcess first({path("s.ply"), "--no-browser", "-q"});
  ASSERT_GT(first.port, 0);
  const Result r =
      run("view " + path("s.ply") + " --no-browser --port " + std::to_string(first.port));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("cannot listen on 127.0.0.1:" + std::to_string(first.port)),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace scalespace::test
