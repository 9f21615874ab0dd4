#pragma once
// What the viewer's router sees of an HTTP request and what it answers, independent of the HTTP
// library: the router and every layer are plain functions of these, testable without a socket
// (ViewerServer converts cpp-httplib's types to and from them).
#include <map>
#include <string>

namespace scalespace::viewer {

struct ViewerRequest {
  std::string method;       // "GET", "POST", ... (HEAD arrives as GET)
  std::string path;         // decoded, without the query string
  std::string host;         // the Host header ("" when absent)
  std::string tokenHeader;  // the X-Scalespace-Token header ("" when absent)
  /// Query parameters (a name given twice sets `malformed`: ambiguous).
  std::map<std::string, std::string> params;
  std::string body;
  /// Why the HTTP layer found the request malformed (a parameter given twice, a Content-Length
  /// that is no number), "" when it did not: a 400 after the guard's checks.
  std::string malformed;
};

struct ViewerResponse {
  int status = 200;
  std::string contentType = "application/octet-stream";
  std::string body;
};

/// A plain-text error answer ("text/plain; charset=utf-8").
ViewerResponse errorResponse(int status, const std::string& message);
/// A JSON answer from an already serialised document.
ViewerResponse jsonResponse(std::string json);
/// A binary answer (little-endian arrays, "application/octet-stream").
ViewerResponse binaryResponse(std::string bytes);

}  // namespace scalespace::viewer
