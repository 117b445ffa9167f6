#!/usr/bin/env bash
# Installs bimart's build and run-time dependencies from Debian 12 packages.
# Idempotent: when everything is present it prints one line and touches nothing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache git
  libtorch-dev libopenblas0-openmp        # networks; OpenMP OpenBLAS (DESIGN §8)
  libgloo-dev                             # headers of libtorch's distributed (c10d/Gloo) training
  libeigen3-dev libyaml-cpp-dev libcgal-dev libceres-dev
  libfmt-dev libspdlog-dev libcli11-dev nlohmann-json3-dev libnanoflann-dev
  libtinygltf-dev libzip-dev zlib1g-dev libstb-dev  # glTF export; .npz files (zlib: CRCs); PNG pictures
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev                           # libFuzzer harnesses (scripts/test.sh --fuzz)
  python3 python3-numpy                              # tools/ converters (numpy only)
  blender chromium                                   # output tests: glTF import, viewer page (docs/outputs.md)
  gnuplot-nox                                        # bimart sweep's table picture (docs/sweeps.md)
  slurm-wlm munge                                    # bimart sweep --backend slurm; its test starts a one-machine cluster (docs/cluster.md)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# node and npm (viewer bundle, glTF validator, Chromium driver): Debian's unless some
# other install already provides the commands (e.g. NodeSource's nodejs, which bundles npm).
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
else
  echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# libtorch calls whatever BLAS the alternatives system selects; make it OpenMP OpenBLAS
# (about 8x faster than the reference BLAS here, and it shares libtorch's OpenMP threads).
arch_lib=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)
for alt in "libblas.so.3-$arch_lib" "liblapack.so.3-$arch_lib"; do
  want=$(update-alternatives --list "$alt" 2>/dev/null | grep openblas-openmp | head -n 1 || true)
  have=$(update-alternatives --query "$alt" 2>/dev/null | awk '/^Value:/ {print $2}')
  if [ -n "$want" ] && [ "$want" != "$have" ]; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo update-alternatives --set "$alt" "$want" >/dev/null
    echo "setup: $alt -> $want"
  fi
done
