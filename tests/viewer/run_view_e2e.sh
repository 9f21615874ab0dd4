#!/usr/bin/env bash
# ctest wrapper of view_e2e.mjs (or, with VIEW_E2E_SCRIPT=view_stack_e2e.mjs, of that script):
# exit 77 (ctest's SKIP_RETURN_CODE) with the reason when Node.js is missing; the scripts themselves
# skip without playwright-core, Chromium or the bundled page.
#   run_view_e2e.sh CLI WORKDIR [script options]
set -uo pipefail
if ! command -v node >/dev/null; then
  echo "SKIP: node not found (Debian package nodejs; scripts/setup.sh installs it)"
  exit 77
fi
exec node "$(dirname "$0")/${VIEW_E2E_SCRIPT:-view_e2e.mjs}" "$@"
