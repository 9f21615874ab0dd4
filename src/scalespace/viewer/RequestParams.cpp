#include "scalespace/viewer/RequestParams.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "scalespace/viewer/RequestError.hpp"

namespace scalespace::viewer {

namespace {

const std::string* find(const ViewerRequest& request, const std::string& name) {
  const auto it = request.params.find(name);
  return it == request.params.end() ? nullptr : &it->second;
}

long long parseInteger(const std::string& text, const std::string& name, long long lo,
                       long long hi) {
  // strtoll alone accepts spaces and a '+'; only plain digits with an optional '-' are meant.
  bool digits = !text.empty() && text.size() <= 19;
  for (std::size_t i = 0; i < text.size() && digits; ++i)
    digits = (text[i] >= '0' && text[i] <= '9') || (i == 0 && text[i] == '-' && text.size() > 1);
  if (!digits) throw RequestError(400, "parameter " + name + ": '" + text + "' is not an integer");
  errno = 0;
  const long long v = std::strtoll(text.c_str(), nullptr, 10);
  if (errno == ERANGE || v < lo || v > hi)
    throw RequestError(400, "parameter " + name + ": " + text + " is outside [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

}  // namespace

std::optional<long long> intParam(const ViewerRequest& request, const std::string& name,
                                  long long lo, long long hi) {
  const std::string* text = find(request, name);
  if (!text) return std::nullopt;
  return parseInteger(*text, name, lo, hi);
}

double doubleParam(const ViewerRequest& request, const std::string& name, double fallback) {
  const std::string* text = find(request, name);
  if (!text) return fallback;
  char* end = nullptr;
  errno = 0;
  const double v = text->empty() ? NAN : std::strtod(text->c_str(), &end);
  if (text->empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v) ||
      std::isspace(static_cast<unsigned char>((*text)[0])))
    throw RequestError(400, "parameter " + name + ": '" + *text + "' is not a finite number");
  return v;
}

std::optional<std::vector<int>> intListParam(const ViewerRequest& request, const std::string& name,
                                             int lo, int hi, std::size_t maxCount) {
  const std::string* text = find(request, name);
  if (!text) return std::nullopt;
  std::vector<int> out;
  if (text->empty()) return out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text->find(',', start);
    const std::string word =
        text->substr(start, comma == std::string::npos ? comma : comma - start);
    if (out.size() == maxCount)
      throw RequestError(
          400, "parameter " + name + ": more than " + std::to_string(maxCount) + " values");
    out.push_back(int(parseInteger(word, name, lo, hi)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

namespace {
std::vector<Index> uint32sFromBody(const std::string& body, std::size_t bound, const char* what,
                                   const char* ofWhat) {
  if (body.size() % 4 != 0)
    throw RequestError(400, "body: " + std::to_string(body.size()) +
                                " bytes is not a whole number of uint32 " + what + "s");
  std::vector<Index> out(body.size() / 4);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const auto* b = reinterpret_cast<const unsigned char*>(body.data() + 4 * k);
    const std::uint32_t v = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 |
                            std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
    if (v >= bound)
      throw RequestError(400, "body: " + std::string(what) + " " + std::to_string(v) +
                                  " is out of range (" + std::to_string(bound) + " " + ofWhat +
                                  ")");
    out[k] = Index(v);
  }
  return out;
}
}  // namespace

std::vector<Index> indicesFromBody(const std::string& body, std::size_t pointCount) {
  return uint32sFromBody(body, pointCount, "point index", "points");
}

std::vector<int> componentIdsFromBody(const std::string& body, std::size_t componentCount) {
  const std::vector<Index> ids =
      uint32sFromBody(body, componentCount, "component id", "components");
  return std::vector<int>(ids.begin(), ids.end());
}

}  // namespace scalespace::viewer
