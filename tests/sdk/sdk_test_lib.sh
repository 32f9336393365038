# Shared by the SDK tests (tests/sdk/CMakeLists.txt): their environment, a
# scratch folder removed on exit, and the checks of an installed tree.
#
# Environment (set by ctest): CASUAL3D_SOURCE_DIR, CASUAL3D_BINARY_DIR,
# CASUAL3D_VERSION (project(VERSION)), CMAKE_COMMAND, CPACK_COMMAND, CXX.

set -euo pipefail

for var in CASUAL3D_SOURCE_DIR CASUAL3D_BINARY_DIR CASUAL3D_VERSION CMAKE_COMMAND; do
  if [ -z "${!var:-}" ]; then
    echo "$(basename "$0"): $var is not set; run the test through ctest" >&2
    exit 2
  fi
done
unset CASUAL3D_VIEWER_DIR  # The installed program must find its own viewer.

test_name="$(basename "$0" .sh)"
fail() {
  echo "$test_name: FAILED: $*" >&2
  exit 1
}
step() { echo "$test_name: $*"; }

scratch="$(mktemp -d "${TMPDIR:-/tmp}/casual3d-${test_name}.XXXXXX")"
trap 'rm -rf "$scratch"' EXIT

# Runs a command quietly; on failure prints its output and fails with `what`.
run_quietly() {
  local what="$1"; shift
  local log="$scratch/last-command.log"
  if ! "$@" >"$log" 2>&1; then
    cat "$log" >&2
    fail "$what"
  fi
}

# Fails unless `tree` holds none of the given strings in any file (binaries
# included) and no file or folder whose name says it is a test.
check_clean_tree() {
  local tree="$1"; shift
  local tests
  tests="$(cd "$tree" && find . -iname '*test*' | sort)"
  [ -z "$tests" ] || fail "$tree holds test files: $(echo "$tests" | tr '\n' ' ')"
  local s hits
  for s in "$@"; do
    hits="$(grep -rlaF -- "$s" "$tree" || true)"
    [ -z "$hits" ] || fail "these installed files contain '$s': $(echo "$hits" | tr '\n' ' ')"
  done
}

# Checks the installed `casual3d` under `root` (a prefix): --version prints the
# project's version, and info and validate accept the spec's valid vectors and
# refuse its invalid ones with one line.
check_installed_program() {
  local casual3d="$1/bin/casual3d"
  [ -x "$casual3d" ] || fail "$casual3d is missing"
  local version
  version="$("$casual3d" --version)"
  [ "$version" = "casual3d $CASUAL3D_VERSION" ] ||
    fail "casual3d --version printed '$version', expected 'casual3d $CASUAL3D_VERSION'"
  local vectors="$CASUAL3D_SOURCE_DIR/spec/vectors" v out
  for v in two-layer-64x32 two-layer-64x32.c3d front-only-48x24 front-only-48x24.c3d; do
    out="$("$casual3d" info "$vectors/$v" 2>&1)" || fail "casual3d info $v: $out"
    echo "$out" | grep -q "^format       casual3d 1\." || fail "casual3d info $v printed: $out"
    out="$("$casual3d" validate "$vectors/$v" 2>&1)" || fail "casual3d validate $v: $out"
  done
  for v in "$vectors"/invalid/*/; do
    if out="$("$casual3d" validate "$v" 2>&1)"; then
      fail "casual3d validate accepted the invalid vector $v"
    fi
    [ "$(echo "$out" | wc -l)" -eq 1 ] || fail "casual3d validate $v: not one line: $out"
  done
}
