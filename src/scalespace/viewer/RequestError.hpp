#pragma once
// Thrown by a layer or a parameter parser for a request the viewer cannot answer: the router turns
// it into an answer with `status` (4xx: the request was wrong) and the message.
#include <stdexcept>
#include <string>

namespace scalespace::viewer {

class RequestError : public std::runtime_error {
 public:
  RequestError(int status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

}  // namespace scalespace::viewer
