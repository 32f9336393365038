#!/usr/bin/env bash
# The SDK as a user gets it from `cmake --install`: installs this build to a
# prefix, moves the prefix (it must be relocatable), then
#  - checks what is installed: public headers only, each compiling on its own,
#    and no test files, build paths or install paths in any file;
#  - builds examples/cpp out of tree with find_package(casual3d) and runs it on
#    a spec vector (its node counts must match spec/vectors/expected.json) and
#    on the package it writes (which the installed casual3d must validate);
#  - builds examples/cpp/pkg-config with pkg-config and runs it;
#  - runs the installed casual3d: --version, info, validate, and view, which
#    must serve the installed viewer.
source "$(dirname "$0")/sdk_test_lib.sh"

installed_at="$scratch/install"
prefix="$scratch/moved/casual3d"
step "cmake --install to $installed_at, moved to $prefix"
run_quietly "cmake --install" "$CMAKE_COMMAND" --install "$CASUAL3D_BINARY_DIR" --prefix "$installed_at"
mkdir -p "$(dirname "$prefix")"
mv "$installed_at" "$prefix"

step "installed files"
for f in bin/casual3d share/casual3d/viewer/casual3d-viewer.js \
         include/casual3d/format/package_reader.h include/casual3d/format/version.h \
         include/casual3d/encoder/package_writer.h lib/libcasual3d_format.a lib/libcasual3d_encoder.a \
         lib/cmake/casual3d/casual3dConfig.cmake lib/cmake/casual3d/casual3dConfigVersion.cmake \
         lib/pkgconfig/casual3d-format.pc; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done
for f in format/parallel.h format/f64x2.h format/sha256.h encoder/level_of_detail.h \
         encoder/gltf_tinygltf.h; do
  [ ! -e "$prefix/include/casual3d/$f" ] || fail "the internal header $f is installed"
done
check_clean_tree "$prefix" "$CASUAL3D_SOURCE_DIR" "$CASUAL3D_BINARY_DIR" "$installed_at"

step "each public header compiles on its own"
(cd "$prefix/include" && find casual3d -name '*.h' | sort) > "$scratch/headers.txt"
while read -r h; do
  echo "#include <$h>" | "$CXX" -std=c++17 -fsyntax-only -Wall -I"$prefix/include" -x c++ - \
    2>"$scratch/header.log" || { cat "$scratch/header.log" >&2; fail "<$h> does not compile on its own"; }
done <"$scratch/headers.txt"

step "examples/cpp with find_package(casual3d)"
run_quietly "configuring examples/cpp" "$CMAKE_COMMAND" -S "$CASUAL3D_SOURCE_DIR/examples/cpp" \
  -B "$scratch/example" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$CXX" \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
found_at="$(sed -n 's/^casual3d_DIR:PATH=//p' "$scratch/example/CMakeCache.txt")"
[ "$found_at" = "$prefix/lib/cmake/casual3d" ] ||
  fail "find_package(casual3d) found $found_at, not the installed $prefix/lib/cmake/casual3d"
run_quietly "building examples/cpp" "$CMAKE_COMMAND" --build "$scratch/example"
vector=two-layer-64x32
"$scratch/example/casual3d_example" "$CASUAL3D_SOURCE_DIR/spec/vectors/$vector.c3d" \
  "$scratch/synthetic" >"$scratch/example.txt" 2>&1 || { cat "$scratch/example.txt" >&2; fail "casual3d_example"; }
cat "$scratch/example.txt"

# Node counts per level of the vector, from spec/vectors/expected.json.
cat >"$scratch/expected.cmake" <<'CMAKE'
file(READ "${EXPECTED}" json)
string(JSON levels LENGTH "${json}" "${VECTOR}")
math(EXPR last "${levels} - 1")
foreach(l RANGE ${last})
  string(JSON front GET "${json}" "${VECTOR}" ${l} present 0)
  string(JSON back GET "${json}" "${VECTOR}" ${l} present 1)
  message("${l} ${front} ${back}")
endforeach()
CMAKE
"$CMAKE_COMMAND" -DEXPECTED="$CASUAL3D_SOURCE_DIR/spec/vectors/expected.json" -DVECTOR="$vector" \
  -P "$scratch/expected.cmake" 2>"$scratch/expected.txt"
[ -s "$scratch/expected.txt" ] || fail "no levels of $vector in spec/vectors/expected.json"
while read -r level front back; do
  # The lines after "level N:" of the vector's part of the output.
  got="$(sed -n "1,/^wrote /p" "$scratch/example.txt" | sed -n "/^level $level:/,/^  back:/p")"
  echo "$got" | grep -q "^  front: $front nodes" || fail "level $level: expected $front front nodes, got: $got"
  echo "$got" | grep -q "^  back: $back nodes" || fail "level $level: expected $back back nodes, got: $got"
done <"$scratch/expected.txt"
grep -q "^wrote $scratch/synthetic: read back with the same nodes and links" "$scratch/example.txt" ||
  fail "casual3d_example did not read back the package it wrote"

step "find_package(casual3d COMPONENTS format), and an unknown component"
mkdir -p "$scratch/components"
cat >"$scratch/components/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.16)
project(components LANGUAGES CXX)
find_package(casual3d CONFIG REQUIRED COMPONENTS format)
if(NOT TARGET casual3d::format OR NOT casual3d_VERSION STREQUAL EXPECTED_VERSION)
  message(FATAL_ERROR "casual3d::format ${casual3d_VERSION}: not as expected")
endif()
find_package(casual3d CONFIG QUIET COMPONENTS format nosuch)
if(casual3d_FOUND)
  message(FATAL_ERROR "find_package(casual3d COMPONENTS nosuch) succeeded")
endif()
CMAKE
sed -i "s/EXPECTED_VERSION/\"$CASUAL3D_VERSION\"/" "$scratch/components/CMakeLists.txt"
run_quietly "find_package(casual3d) with components" "$CMAKE_COMMAND" -S "$scratch/components" \
  -B "$scratch/components/build" -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF

step "the installed casual3d"
check_installed_program "$prefix"
out="$("$prefix/bin/casual3d" validate "$scratch/synthetic" 2>&1)" || fail "validate of the example's package: $out"
out="$("$prefix/bin/casual3d" info "$scratch/synthetic")"
echo "$out" | grep -q "written by casual3d $CASUAL3D_VERSION\$" ||
  fail "the example's package does not name casual3d $CASUAL3D_VERSION as its writer: $out"

step "examples/cpp/pkg-config with pkg-config"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
modversion="$(pkg-config --modversion casual3d-format)"
[ "$modversion" = "$CASUAL3D_VERSION" ] || fail "pkg-config --modversion casual3d-format: $modversion"
cp -r "$CASUAL3D_SOURCE_DIR/examples/cpp/pkg-config" "$scratch/pkg-config-example"
run_quietly "make in examples/cpp/pkg-config" make -C "$scratch/pkg-config-example" CXX="$CXX"
out="$("$scratch/pkg-config-example/manifest_info" "$CASUAL3D_SOURCE_DIR/spec/vectors/$vector")" ||
  fail "manifest_info: $out"
echo "$out"
echo "$out" | grep -q "^$CASUAL3D_SOURCE_DIR/spec/vectors/$vector: 64x32, package format 1\.[0-9]*, $(wc -l <"$scratch/expected.txt") levels" ||
  fail "manifest_info printed: $out"
unset PKG_CONFIG_PATH

step "casual3d view serves the installed viewer"
"$prefix/bin/casual3d" view "$CASUAL3D_SOURCE_DIR/spec/vectors/$vector" --port 0 \
  >"$scratch/view.txt" 2>&1 &
view_pid=$!
trap 'kill "$view_pid" 2>/dev/null || true; rm -rf "$scratch"' EXIT
port=""
for _ in $(seq 100); do
  port="$(sed -n 's|.*http://127\.0\.0\.1:\([0-9]*\)/.*|\1|p' "$scratch/view.txt")"
  [ -n "$port" ] && break
  kill -0 "$view_pid" 2>/dev/null || fail "casual3d view exited: $(cat "$scratch/view.txt")"
  sleep 0.1
done
[ -n "$port" ] || fail "casual3d view printed no address: $(cat "$scratch/view.txt")"
viewer_js="$prefix/share/casual3d/viewer/casual3d-viewer.js"
exec 3<>"/dev/tcp/127.0.0.1/$port"
printf 'GET /viewer/casual3d-viewer.js HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n' >&3
cat <&3 >"$scratch/response"
exec 3<&-
head -n 1 "$scratch/response" | grep -q "^HTTP/1\.[01] 200" ||
  fail "GET /viewer/casual3d-viewer.js: $(head -n 1 "$scratch/response")"
tail -c "$(stat -c %s "$viewer_js")" "$scratch/response" | cmp -s - "$viewer_js" ||
  fail "GET /viewer/casual3d-viewer.js did not return the installed $viewer_js"
kill "$view_pid"
wait "$view_pid" 2>/dev/null || true

# Without the installed viewer the program says where it looked.
mv "$prefix/share/casual3d/viewer" "$prefix/share/casual3d/viewer.away"
if out="$("$prefix/bin/casual3d" view "$CASUAL3D_SOURCE_DIR/spec/vectors/$vector" --port 0 2>&1)"; then
  fail "casual3d view ran without its viewer"
fi
echo "$out" | grep -qF "$prefix/share/casual3d/viewer" ||
  fail "casual3d view without its viewer does not name $prefix/share/casual3d/viewer: $out"
step "passed"
