#pragma once
// The page's files (index.html and the esbuild bundle app.js), read once at start-up: the server
// answers from memory, so no request path ever reaches the file system.
#include <string>

namespace scalespace::viewer {

struct PageAssets {
  std::string indexHtml;  // with the placeholder %SCALESPACE_TOKEN% for the token
  std::string appJs;
  /// Empty when both were found; else why not (the page then says so, the API still works).
  std::string missingReason;
};

/// Reads DIR/index.html and DIR/app.js.
PageAssets readPageAssets(const std::string& directory);

/// The folder of the page beside a program at `programPath`: <dir>/viewer-page (the build tree)
/// or <dir>/../share/scalespace/viewer-page (an installed copy), the first holding index.html;
/// "" when neither does.
std::string findPageDirectory(const std::string& programPath);

}  // namespace scalespace::viewer
