#!/usr/bin/env bash
# Installs bimart into a scratch prefix, builds examples/plugin against it with
# find_package(bimart), and runs the example pipeline with the installed program.
# Usage: example_plugin_test.sh BUILD_DIR SOURCE_DIR SCRATCH_PREFIX
set -euo pipefail
build=$1 src=$2 prefix=$3

rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" > "$prefix.install.log" 2>&1 || { cat "$prefix.install.log"; exit 1; }
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$src/examples/plugin" -B "$prefix/example-build" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" > "$prefix/configure.log" 2>&1 || { cat "$prefix/configure.log"; exit 1; }
cmake --build "$prefix/example-build" -j 2 > "$prefix/build.log" 2>&1 || { cat "$prefix/build.log"; exit 1; }

bimart="$prefix/bin/bimart"
lib="$prefix/example-build/libbimart_hinge_sweep.so"
test -f "$lib"

# The installed program finds the installed built-in plug-ins, plus the example.
"$bimart" --plugin "$lib" plugins > "$prefix/plugins.txt"
grep -q "trajectory.hinge_sweep  (kind trajectory)" "$prefix/plugins.txt"
grep -q "export.states_csv" "$prefix/plugins.txt"
grep -q "$prefix/lib/bimart/plugins/libbimart_smoke.so" "$prefix/plugins.txt"

# Run the example pipeline; the lid ends at 1.2 rad after 30 frames.
out="$prefix/out/sweep.csv"
"$bimart" --plugin "$lib" run "$src/examples/plugin/pipeline.yaml" --set write.path="$out"
test "$(wc -l < "$out")" -eq 31
tail -n 1 "$out" | grep -q "^29,0.966666667,1.20000005,"

# The same library named in the pipeline file, and found through BIMART_PLUGIN_PATH.
sed "s|^stages:|plugins: [$lib]\nstages:|" "$src/examples/plugin/pipeline.yaml" > "$prefix/with_plugins.yaml"
"$bimart" run "$prefix/with_plugins.yaml" --set write.path="$prefix/out/sweep2.csv"
cmp "$out" "$prefix/out/sweep2.csv"
BIMART_PLUGIN_PATH="$prefix/example-build" "$bimart" graph "$src/examples/plugin/pipeline.yaml" | grep -q "sweep  \[trajectory.hinge_sweep\]"
echo "example plug-in: built against the installed package and ran"
