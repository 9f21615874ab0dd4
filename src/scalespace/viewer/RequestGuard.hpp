#pragma once
// The checks every request passes before the router looks at its path: the Host header must name
// this server on the loopback (a DNS-rebinding page reaches 127.0.0.1 under a foreign name), and
// the token must be given (query parameter `token` or header X-Scalespace-Token).
#include <optional>
#include <string>

#include "scalespace/viewer/ViewerHttp.hpp"

namespace scalespace::viewer {

struct GuardSettings {
  std::string token;
  int port = 0;  // the port actually bound
};

/// True for "127.0.0.1:<port>" and "localhost:<port>" (case-insensitive name), nothing else.
bool isLocalHost(const std::string& host, int port);

/// A 403 answer (saying which check failed) when the request must be refused, else nothing.
std::optional<ViewerResponse> refusal(const ViewerRequest& request, const GuardSettings& settings);

}  // namespace scalespace::viewer
