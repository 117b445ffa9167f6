#!/usr/bin/env bash
# Builds the viewer script: three.js (version pinned in package-lock.json) and viewer.js in
# one minified file, OUT (default: viewer_bundle.js here). Needs the npm registry only when
# node_modules/ is missing; does nothing when OUT is newer than its sources. Never fails the
# build: without npm or network it warns, and `bimart view` then says what is missing.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-$here/viewer_bundle.js}
modules=${2:-$here/node_modules}
if [ -f "$out" ] && [ "$out" -nt "$here/viewer.js" ] && [ "$out" -nt "$here/package-lock.json" ]; then exit 0; fi
warn() { echo "viewer bundle: $* (bimart view needs it; see docs/outputs.md)" >&2; exit 0; }
command -v npm >/dev/null || warn "npm not found, not built"
work=$(dirname "$modules")
if [ ! -x "$modules/.bin/esbuild" ]; then
  mkdir -p "$work"
  cp "$here/package.json" "$here/package-lock.json" "$work/"
  (cd "$work" && npm ci --no-audit --no-fund --loglevel=error) >&2 || warn "npm ci failed (offline?), not built"
fi
mkdir -p "$(dirname "$out")"
NODE_PATH="$modules" "$modules/.bin/esbuild" "$here/viewer.js" --bundle --minify --format=iife --target=es2020 \
  --legal-comments=none --log-level=warning --outfile="$out.tmp" || warn "esbuild failed"
version=$(node -p "require('$modules/three/package.json').version" 2>/dev/null || echo unknown)
{ echo "/* three.js $version (MIT License, Copyright 2010-2025 three.js authors) and bimart's viewer.js, bundled by esbuild */"
  cat "$out.tmp"; } > "$out.tmp2" && rm -f "$out.tmp" && mv "$out.tmp2" "$out"
echo "viewer bundle: wrote $out ($(stat -c %s "$out") bytes)"
