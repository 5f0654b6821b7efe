#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The editor's page (web/): its dependencies, and its browser tests against the program.
#   scripts/web.sh --test     web/tests/run.mjs: `trivcon edit` ($BUILD_DIR/trivcon, default build/) on the bundled
#                             cube sphere, driven in headless Chromium (puppeteer-core); run by scripts/test.sh
#   scripts/web.sh --bundle   only bundle the page into web/dist/app.js (the CMake build does this itself, into
#                             the build folder, and embeds it in the program)
# Installs what it needs first (scripts/deps.sh --web).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh --web
BUILD_DIR=${BUILD_DIR:-build}
case "${1:-}" in
  --test)
    [ -x "$BUILD_DIR/trivcon" ] || { echo "web.sh: $BUILD_DIR/trivcon not built (scripts/build.sh)" >&2; exit 1; }
    start=$(date +%s)
    node web/tests/run.mjs --trivcon "$BUILD_DIR/trivcon"
    echo "== web: browser tests in $(($(date +%s) - start)) s"
    ;;
  --bundle)
    (cd web && npm run --silent build)
    ;;
  *) echo "usage: scripts/web.sh --test | --bundle" >&2; exit 2 ;;
esac
