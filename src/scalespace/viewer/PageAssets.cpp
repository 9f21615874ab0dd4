#include "scalespace/viewer/PageAssets.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace scalespace::viewer {

namespace fs = std::filesystem;

namespace {
bool readText(const fs::path& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  out = s.str();
  return bool(in) || in.eof();
}
}  // namespace

PageAssets readPageAssets(const std::string& directory) {
  PageAssets assets;
  if (directory.empty()) {
    assets.missingReason =
        "the viewer page was not built (no viewer-page folder beside the "
        "program): run scripts/setup_web.sh, then rebuild";
    return assets;
  }
  for (const char* name : {"index.html", "app.js"}) {
    std::string& out = std::string(name) == "app.js" ? assets.appJs : assets.indexHtml;
    if (!readText(fs::path(directory) / name, out)) {
      assets.missingReason =
          "the viewer page is incomplete: " + (fs::path(directory) / name).string() +
          " is missing (npm was not available at build time?): run "
          "scripts/setup_web.sh, then rebuild";
      return assets;
    }
  }
  return assets;
}

std::string findPageDirectory(const std::string& programPath) {
  std::error_code ec;
  const fs::path dir = fs::absolute(programPath, ec).parent_path();
  for (const fs::path& candidate :
       {dir / "viewer-page", dir / ".." / "share" / "scalespace" / "viewer-page"})
    if (fs::exists(candidate / "index.html", ec)) return candidate.lexically_normal().string();
  return "";
}

}  // namespace scalespace::viewer
