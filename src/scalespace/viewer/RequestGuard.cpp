#include "scalespace/viewer/RequestGuard.hpp"

#include <cctype>

#include "scalespace/viewer/ViewerToken.hpp"

namespace scalespace::viewer {

bool isLocalHost(const std::string& host, int port) {
  const std::string suffix = ":" + std::to_string(port);
  if (host.size() <= suffix.size() ||
      host.compare(host.size() - suffix.size(), suffix.size(), suffix))
    return false;
  std::string name = host.substr(0, host.size() - suffix.size());
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  return name == "127.0.0.1" || name == "localhost";
}

std::optional<ViewerResponse> refusal(const ViewerRequest& request, const GuardSettings& settings) {
  if (!isLocalHost(request.host, settings.port))
    return errorResponse(
        403, "forbidden: the Host header must be 127.0.0.1:" + std::to_string(settings.port) +
                 " or localhost:" + std::to_string(settings.port));
  const auto it = request.params.find("token");
  const std::string& given = it != request.params.end() ? it->second : request.tokenHeader;
  if (given.empty() || !tokensEqual(given, settings.token))
    return errorResponse(403,
                         "forbidden: a missing or wrong token (use the URL that "
                         "`scalespace view` printed)");
  return std::nullopt;
}

}  // namespace scalespace::viewer
