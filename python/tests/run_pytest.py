"""Runs pytest on python/tests for ctest; exits 77 (ctest: skipped) with a
message when pytest or numpy is missing (Debian: python3-pytest python3-numpy)."""

import importlib.util
import sys

missing = [name for name in ("pytest", "numpy") if importlib.util.find_spec(name) is None]
if missing:
    print(f"skipped: {' and '.join(missing)} not installed for {sys.executable} "
          "(Debian: python3-pytest python3-numpy)")
    sys.exit(77)

import pytest  # noqa: E402

sys.exit(pytest.main(sys.argv[1:]))
