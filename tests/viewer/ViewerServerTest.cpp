// The viewer's server on the loopback: bound to 127.0.0.1 only, the rules of the router over real
// HTTP, malformed and oversized requests answered with a 4xx (the server keeps serving), and a
// bounded load of concurrent requests with no failure.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <sstream>
#include <thread>

#include "ViewerTestModel.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/viewer/ViewerServer.hpp"

// Last: its system headers define `_res` (resolv.h), a parameter name in Eigen's headers.
#include <httplib.h>  // NOLINT(llvm-include-order)

namespace scalespace::test {
namespace {

// Sends `raw` on a fresh connection and returns whatever comes back before the server closes it
// (or 2 s pass, for a request the server still waits the rest of).
std::string rawExchange(int port, const std::string& raw) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(std::uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return "connect failed";
  }
  timeval timeout{2, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  std::size_t sent = 0;
  while (sent < raw.size()) {
    const ssize_t n = ::send(fd, raw.data() + sent, raw.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server may close early on a request it refuses
    sent += std::size_t(n);
  }
  // No shutdown(SHUT_WR): httplib takes a half-closed connection for a gone client and answers
  // nothing. Requests carry "Connection: close" or are refused, so the server closes.
  std::string answer;
  char buffer[4096];
  for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) {
    answer.append(buffer, std::size_t(n));
    // One whole answer is enough: a kept-alive connection would otherwise wait for the timeout.
    const std::size_t end = answer.find("\r\n\r\n");
    const std::size_t length = answer.find("Content-Length: ");
    if (end != std::string::npos && length != std::string::npos && length < end &&
        answer.size() >= end + 4 + std::stoul(answer.substr(length + 16)))
      break;
  }
  ::close(fd);
  return answer;
}

int statusOf(const std::string& answer) {
  if (answer.compare(0, 9, "HTTP/1.1 ") != 0) return -1;
  return std::atoi(answer.c_str() + 9);
}

class ViewerServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    viewer::ViewerServerOptions options;
    options.maxBodyBytes = 4096;
    server_ = std::make_unique<viewer::ViewerServer>(smallRouter(), options);
    port_ = server_->start();
    ASSERT_GT(port_, 0);
  }
  std::string host() const { return "127.0.0.1:" + std::to_string(port_); }
  std::string get(const std::string& target, const std::string& hostHeader = "") const {
    return rawExchange(port_, "GET " + target + " HTTP/1.1\r\nHost: " +
                                  (hostHeader.empty() ? host() : hostHeader) +
                                  "\r\nConnection: close\r\n\r\n");
  }
  bool stillServes() const { return statusOf(get("/api/manifest?token=" + kToken)) == 200; }
  std::unique_ptr<viewer::ViewerServer> server_;
  int port_ = 0;
};

TEST_F(ViewerServerTest, ListensOnTheLoopbackOnly) {
  // /proc/net/tcp lists each listening socket's local address: 0100007F is 127.0.0.1.
  std::ifstream tcp("/proc/net/tcp");
  std::string line;
  char portHex[8];
  std::snprintf(portHex, sizeof portHex, "%04X", port_);
  bool found = false;
  while (std::getline(tcp, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state;
    fields >> slot >> local >> remote >> state;
    if (state == "0A" && local.size() > 9 && local.substr(9) == portHex) {
      EXPECT_EQ(local.substr(0, 8), "0100007F") << line;
      found = true;
    }
  }
  EXPECT_TRUE(found) << "no listening socket on port " << port_;
}

TEST_F(ViewerServerTest, AppliesTheRulesOverHttp) {
  EXPECT_EQ(statusOf(get("/api/manifest?token=" + kToken)), 200);
  EXPECT_EQ(statusOf(get("/api/manifest")), 403);
  EXPECT_EQ(statusOf(get("/api/manifest?token=wrong")), 403);
  EXPECT_EQ(
      statusOf(get("/api/manifest?token=" + kToken, "attacker.example:" + std::to_string(port_))),
      403);
  EXPECT_EQ(statusOf(get("/../../etc/passwd?token=" + kToken)), 404);
  EXPECT_EQ(statusOf(get("/%2e%2e/%2e%2e/etc/passwd?token=" + kToken)), 404);
  EXPECT_EQ(statusOf(get("/api/cloud/..%2f..%2fetc%2fpasswd?token=" + kToken)), 404);
  EXPECT_EQ(statusOf(get("/api/manifest?token=" + kToken + "&token=wrong")), 400);
  // The token travels in the URL: the answers tell the browser not to pass it on or cache it.
  const std::string answer = get("/?token=" + kToken);
  EXPECT_NE(answer.find("Referrer-Policy: no-referrer"), std::string::npos);
  EXPECT_NE(answer.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  EXPECT_NE(answer.find("Cache-Control: no-store"), std::string::npos);
}

TEST_F(ViewerServerTest, AnswersMalformedRequestsWithA4xxAndKeepsServing) {
  const std::string h = "Host: " + host() + "\r\n";
  const std::string requests[] = {
      "GARBAGE\r\n\r\n",
      "GET\r\n\r\n",
      "GET /api/manifest\r\n\r\n",
      "GET /api/manifest HTTP/9.9\r\n" + h + "\r\n",
      "GET /api/manifest?token=" + kToken + " HTTP/1.1\r\n" + h + h + "\r\n",  // two Hosts
      "GET /api/manifest?token=" + kToken + " HTTP/1.1\r\n" + h + "X: " + std::string(20000, 'a') +
          "\r\n\r\n",                                                    // header beyond the limit
      "GET /" + std::string(20000, 'a') + " HTTP/1.1\r\n" + h + "\r\n",  // URI beyond the limit
      "POST /api/planes/brush?token=" + kToken + " HTTP/1.1\r\n" + h +
          "Content-Length: abc\r\n\r\n",
      "POST /api/planes/brush?token=" + kToken + " HTTP/1.1\r\n" + h +
          "Content-Length: 100000\r\n\r\n" + std::string(100000, '\0'),  // body over the limit
      "POST /api/planes/brush?token=" + kToken + " HTTP/1.1\r\n" + h +
          "Content-Length: 8\r\n\r\n\1\2",  // truncated body, then the client closes
      "POST /api/planes/brush?token=" + kToken + " HTTP/1.1\r\n" + h +
          "Transfer-Encoding: chunked\r\n\r\nzz\r\n",  // bad chunk size
      "GET /api/planes/labels?token=" + kToken + "&level=%zz HTTP/1.1\r\n" + h + "\r\n",
      std::string("\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03", 11),  // a TLS hello
      "\r\n\r\n\r\n",
  };
  for (const std::string& raw : requests) {
    const std::string answer = rawExchange(port_, raw);
    const int status = statusOf(answer);
    // Either a 4xx, or the connection closed without an answer (a truncated request).
    EXPECT_TRUE(answer.empty() || (status >= 400 && status < 500))
        << "request: " << raw.substr(0, 130) << "\nanswer: " << answer.substr(0, 200);
    ASSERT_TRUE(stillServes()) << "after: " << raw.substr(0, 80);
  }
}

TEST_F(ViewerServerTest, SurvivesAThousandConcurrentRequests) {
  constexpr int kThreads = 8, kPerThread = 125;
  std::atomic<int> wrong{0}, answered{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      httplib::Client client("127.0.0.1", port_);
      client.set_connection_timeout(5, 0);
      client.set_read_timeout(10, 0);
      for (int k = 0; k < kPerThread; ++k) {
        const int kind = (t + k) % 4;
        httplib::Result r =
            kind == 0 ? client.Get(("/api/planes/labels?min_persistence=1&token=" + kToken).c_str())
            : kind == 1 ? client.Get("/api/cloud/positions?token=wrong")
            : kind == 2 ? client.Post(("/api/planes/brush?token=" + kToken).c_str(),
                                      indexBody({1, 4, 6}), "application/octet-stream")
                        : client.Get(("/api/planes/labels?level=x&token=" + kToken).c_str());
        if (!r) {
          ++wrong;
          continue;
        }
        ++answered;
        const int expected[] = {200, 403, 200, 400};
        if (r->status != expected[kind]) ++wrong;
        if (kind == 0 && r->body.size() != 8 * 4) ++wrong;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(answered.load(), kThreads * kPerThread);
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_TRUE(stillServes());
}

TEST_F(ViewerServerTest, RefusesAPortInUse) {
  viewer::ViewerServerOptions options;
  options.port = port_;
  viewer::ViewerServer second(smallRouter(), options);
  EXPECT_THROW(second.start(), Error);
}

TEST(ViewerServer, StopsPromptlyAfterStart) {
  viewer::ViewerServer server(smallRouter(), {});
  EXPECT_GT(server.start(), 0);
  server.stop();
  server.stop();  // twice is harmless (the destructor stops again)
}

}  // namespace
}  // namespace scalespace::test
