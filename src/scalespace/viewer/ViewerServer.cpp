#include "scalespace/viewer/ViewerServer.hpp"

#include <httplib.h>

#include <chrono>
#include <thread>
#include <utility>

#include "scalespace/core/Error.hpp"

namespace scalespace::viewer {

struct ViewerServer::Impl {
  httplib::Server server;
  std::thread thread;
};

namespace {

// The page needs nothing from elsewhere: scripts, data and styles come from this origin only, it
// cannot be framed, and the token in its URL is not sent on as a referrer.
void addSecurityHeaders(httplib::Response& res) {
  res.set_header(
      "Content-Security-Policy",
      "default-src 'self'; img-src 'self' data: blob:; style-src 'self' 'unsafe-inline'; "
      "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Frame-Options", "DENY");
}

void answer(const ViewerRouter& router, const httplib::Request& req, httplib::Response& res) {
  ViewerRequest request;
  request.method = req.method == "HEAD" ? "GET" : req.method;
  request.path = req.path;
  // Two Host headers: none is trusted (the guard then refuses the empty one).
  if (req.get_header_value_count("Host") == 1) request.host = req.get_header_value("Host");
  request.tokenHeader = req.get_header_value("X-Scalespace-Token");
  for (const auto& [name, value] : req.params)
    if (!request.params.emplace(name, value).second)
      request.malformed = "parameter " + name + " given twice";
  // httplib reads a Content-Length that is not a number as 0 and goes on: refuse it instead.
  if (req.has_header("Content-Length")) {
    const std::string length = req.get_header_value("Content-Length");
    if (length.empty() || length.find_first_not_of("0123456789") != std::string::npos)
      request.malformed = "Content-Length '" + length + "' is not a number";
  }
  request.body = req.body;
  ViewerResponse response = router.route(request);
  res.status = response.status;
  res.set_content(std::move(response.body), response.contentType.c_str());
  addSecurityHeaders(res);
}

}  // namespace

ViewerServer::ViewerServer(std::unique_ptr<ViewerRouter> router, ViewerServerOptions options)
    : router_(std::move(router)), options_(options), impl_(std::make_unique<Impl>()) {}

ViewerServer::~ViewerServer() { stop(); }

int ViewerServer::start() {
  httplib::Server& server = impl_->server;
  const ViewerRouter& router = *router_;
  auto handler = [&router](const httplib::Request& req, httplib::Response& res) {
    answer(router, req, res);
  };
  // Every method reaches the router, which refuses what it does not serve (405/404) after the
  // token and Host checks; nothing is mapped to files (no set_mount_point).
  server.Get(".*", handler);
  server.Post(".*", handler);
  server.Put(".*", handler);
  server.Patch(".*", handler);
  server.Delete(".*", handler);
  server.Options(".*", handler);
  // httplib's default also sets SO_REUSEPORT, with which a second server (ours or another program
  // of the same user) binds the same port and silently takes half of the connections: only
  // SO_REUSEADDR (a restart right after a stop still binds), so a port in use is an error.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  server.set_payload_max_length(options_.maxBodyBytes);
  server.set_read_timeout(10, 0);
  server.set_write_timeout(60, 0);
  server.set_keep_alive_max_count(1000);
  server.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
        res.status = 500;
        res.set_content("internal error\n", "text/plain; charset=utf-8");
      });
  int port = options_.port;
  if (port == 0) {
    port = server.bind_to_any_port("127.0.0.1");
    if (port <= 0) throw Error("the viewer cannot bind a port on 127.0.0.1");
  } else if (!server.bind_to_port("127.0.0.1", port)) {
    throw Error("the viewer cannot listen on 127.0.0.1:" + std::to_string(port) +
                " (in use? try another --port, or 0 for any free one)");
  }
  router_->setPort(port);
  impl_->thread = std::thread([&server] { server.listen_after_bind(); });
  // stop() before the loop runs would not end it (httplib's stop() only acts on a running
  // server): wait for it. The socket listens since the bind, so no connection is lost meanwhile.
  while (!server.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return port;
}

void ViewerServer::stop() {
  if (!impl_) return;
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace scalespace::viewer
