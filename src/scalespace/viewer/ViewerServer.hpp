#pragma once
// The HTTP side of the viewer (cpp-httplib): listens on 127.0.0.1 only, hands every request to a
// ViewerRouter, adds the headers that keep the page and its data to this origin.
#include <memory>

#include "scalespace/viewer/ViewerRouter.hpp"

namespace scalespace::viewer {

struct ViewerServerOptions {
  int port = 0;                        // 0: any free port
  std::size_t maxBodyBytes = 1 << 20;  // larger request bodies get 413
};

class ViewerServer {
 public:
  ViewerServer(std::unique_ptr<ViewerRouter> router, ViewerServerOptions options);
  ~ViewerServer();
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  /// Binds 127.0.0.1 and serves on a background thread; returns the port. Throws Error naming
  /// the port when it cannot bind (in use, not allowed).
  int start();
  /// Stops serving and joins the thread (also done by the destructor).
  void stop();
  const ViewerRouter& router() const { return *router_; }

 private:
  struct Impl;
  std::unique_ptr<ViewerRouter> router_;
  ViewerServerOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scalespace::viewer
