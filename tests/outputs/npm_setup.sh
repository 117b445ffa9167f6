#!/usr/bin/env bash
# Installs the test tools pinned in tests/outputs/package-lock.json (gltf-validator,
# puppeteer-core) into DIR/node_modules with `npm ci`, once; needs the npm registry then.
# Offline without them the tool tests skip (or fail with CI set).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
dir=$1
if [ -f "$dir/node_modules/.package-lock.json" ] && [ "$dir/node_modules/.package-lock.json" -nt "$here/package-lock.json" ]; then
  echo "npm test tools: up to date in $dir"; exit 0
fi
command -v npm >/dev/null || { echo "npm test tools: npm not found (install nodejs/npm)"; [ -z "${CI:-}" ] || exit 1; exit 0; }
mkdir -p "$dir"
cp "$here/package.json" "$here/package-lock.json" "$dir/"
if (cd "$dir" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error); then
  echo "npm test tools: installed in $dir"
else
  echo "npm test tools: npm ci failed (offline?)"; [ -z "${CI:-}" ] || exit 1
fi
