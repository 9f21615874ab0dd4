#!/usr/bin/env bash
# Installs the npm packages of the viewer page (three, esbuild, playwright-core: exact versions of
# src/scalespace/viewer/web/package-lock.json) into that folder's node_modules, which CMake's
# bundling step (cmake/ViewerPage.cmake) and the end-to-end test use. Idempotent: nothing to do when
# node_modules matches the lock file. Never fatal: without npm or the registry the project still
# builds (without the page) and the viewer's end-to-end test skips, saying why.
set -uo pipefail
web="$(cd "$(dirname "$0")/.." && pwd)/src/scalespace/viewer/web"
stamp="$web/node_modules/.package-lock.json"
if [[ -f "$stamp" && "$stamp" -nt "$web/package-lock.json" ]]; then
  echo "setup_web: node_modules up to date"
  exit 0
fi
if ! command -v npm >/dev/null; then
  echo "setup_web: warning: npm not found; the viewer page will not be bundled" >&2
  exit 0
fi
echo "setup_web: npm ci in $web"
# --ignore-scripts: nothing runs at install (esbuild's binary comes as its platform package).
if ! (cd "$web" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error); then
  echo "setup_web: warning: npm ci failed; the viewer page will not be bundled" >&2
fi
exit 0
