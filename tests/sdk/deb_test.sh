#!/usr/bin/env bash
# The Debian package: cpack -G DEB builds it with its runtime dependencies
# computed by dpkg-shlibdeps; unpacked with dpkg -x into a scratch root, it
# holds no test files and no paths of this machine, and its casual3d prints the
# project's version and runs info and validate on the spec vectors.
source "$(dirname "$0")/sdk_test_lib.sh"

[ -n "${CPACK_COMMAND:-}" ] || fail "CPACK_COMMAND is not set; run the test through ctest"

step "cpack -G DEB"
run_quietly "cpack -G DEB" "$CPACK_COMMAND" -G DEB --config "$CASUAL3D_BINARY_DIR/CPackConfig.cmake" \
  -B "$scratch/cpack"
debs=("$scratch"/cpack/*.deb)
[ "${#debs[@]}" -eq 1 ] && [ -f "${debs[0]}" ] || fail "expected one .deb in $scratch/cpack, found: ${debs[*]}"
deb="${debs[0]}"
echo "$test_name: $(basename "$deb"), $(stat -c %s "$deb") bytes"

version="$(dpkg-deb -f "$deb" Version)"
[ "$version" = "$CASUAL3D_VERSION" ] || fail "the package's version is $version, not $CASUAL3D_VERSION"
depends="$(dpkg-deb -f "$deb" Depends)"
echo "$test_name: Depends: $depends"
# dpkg-shlibdeps names the package of every shared library the program links.
for lib in libc6 libwebp libopenexr libstdc++6; do
  echo "$depends" | grep -q "$lib" || fail "Depends does not name $lib: $depends"
done

step "dpkg -x"
dpkg -x "$deb" "$scratch/root"
root="$scratch/root/usr"
for f in share/casual3d/viewer/casual3d-viewer.js include/casual3d/format/package_reader.h \
         lib/cmake/casual3d/casual3dConfig.cmake lib/pkgconfig/casual3d-format.pc; do
  [ -e "$root/$f" ] || fail "the package lacks /usr/$f"
done
check_clean_tree "$scratch/root" "$CASUAL3D_SOURCE_DIR" "$CASUAL3D_BINARY_DIR" "$scratch"
check_installed_program "$root"
step "passed"
