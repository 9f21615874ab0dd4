#!/usr/bin/env bash
# ctest wrapper of view_e2e.mjs: exit 77 (ctest's SKIP_RETURN_CODE) with the reason when Node.js is
# missing; the script itself skips without playwright-core, Chromium or the bundled page.
#   run_view_e2e.sh CLI WORKDIR [view_e2e.mjs options]
set -uo pipefail
if ! command -v node >/dev/null; then
  echo "SKIP: node not found (Debian package nodejs; scripts/setup.sh installs it)"
  exit 77
fi
exec node "$(dirname "$0")/view_e2e.mjs" "$@"
