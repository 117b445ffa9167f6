#!/usr/bin/env bash
# Installs what is missing, builds, and runs the method on the shipped default: the first
# example trajectory through pipelines/bimart.yaml with the models in models/, 3 samples.
# Extra arguments go to `bimart run` (e.g. --samples 5 --seed 2 --out out/mine).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
build=${BIMART_BUILD_DIR:-$root/build}
cd "$root"
# Defaults for what the arguments leave out.
out=out/bimart
args=("$@")
for ((i = 0; i < ${#args[@]}; ++i)); do
  case ${args[i]} in
    --out) out=${args[i + 1]:-$out} ;;
    --out=*) out=${args[i]#--out=} ;;
  esac
done
has() { local a; for a in "${args[@]}"; do [[ $a == "$1" || $a == "$1="* ]] && return 0; done; return 1; }
defaults=()
has --samples || defaults+=(--samples 3)
has --out || defaults+=(--out "$out")
# The samples of an earlier run are replaced, not mixed with this one's.
rm -f "$out"/sample_*.npz "$out"/sample_*.glb
"$build/bin/bimart" run pipelines/bimart.yaml "${defaults[@]}" "$@"
echo
echo "viewer:  $out/viewer.html  (open it in a browser; offline, all samples)"
echo "glTF:    $(ls "$out"/sample_*.glb | tr '\n' ' ') (Blender: File > Import > glTF 2.0)"
echo "metrics: $out/metrics.json"
echo "motion:  $out/sample_*.npz  (bimart eval $out)"
