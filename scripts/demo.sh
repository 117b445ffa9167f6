#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on the shipped default.
# (Until the generation stages land, the default is the smoke pipeline.)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
build=${BIMART_BUILD_DIR:-$root/build}
cd "$root"
"$build/bin/bimart" run pipelines/smoke.yaml "$@"
