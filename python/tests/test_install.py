"""`cmake --install` puts the package into the prefix's site-packages, from
where it imports on its own, relocatable (no build paths in the module)."""

import os
import shutil
import subprocess
import sys

import pytest

import casual3d


def test_installed_package_imports_from_a_moved_prefix(tmp_path):
    build = os.environ.get("CASUAL3D_BINARY_DIR")
    pythondir = os.environ.get("CASUAL3D_PYTHONDIR")
    if not build or not pythondir:
        pytest.skip("not run through ctest (CASUAL3D_BINARY_DIR, CASUAL3D_PYTHONDIR unset)")
    cmake = os.environ.get("CMAKE_COMMAND", "cmake")
    out = subprocess.run([cmake, "--install", build, "--component", "python",
                          "--prefix", tmp_path / "prefix"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    shutil.move(tmp_path / "prefix", tmp_path / "moved")
    package = tmp_path / "moved" / pythondir / "casual3d"
    modules = [p for p in package.iterdir() if p.name.startswith("_casual3d")]
    assert len(modules) == 1 and (package / "__init__.py").exists()
    assert build.encode() not in modules[0].read_bytes()
    env = {"PATH": os.environ.get("PATH", ""), "PYTHONPATH": str(tmp_path / "moved" / pythondir)}
    out = subprocess.run([sys.executable, "-c",
                          "import casual3d; print(casual3d.__file__, casual3d.__version__)"],
                         capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    path, version = out.stdout.split()
    assert path.startswith(str(package)) and version == casual3d.__version__


def test_version_is_the_project_version():
    import re
    from conftest import SOURCE_DIR
    project = re.search(r"project\(casual3d VERSION ([0-9.]+)",
                        (SOURCE_DIR / "CMakeLists.txt").read_text())
    assert casual3d.__version__ == project.group(1)
